#include "trivox/geom/validity.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include "trivox/error.hpp"
#include "trivox/limits.hpp"
#include "trivox/spline/calculus.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::geom {

namespace {

template <int P>
using Piece = spline::TensorSpline<P>;

/// The control-point index of corner `c` (bit d: last along direction d).
template <int P>
typename Piece<P>::Index corner_index(const Piece<P>& s, int c) {
  typename Piece<P>::Index i{};
  for (int d = 0; d < P; ++d) i[static_cast<std::size_t>(d)] = (c >> d) & 1 ? s.count(d) - 1 : 0;
  return i;
}

template <int P>
typename Piece<P>::Params corner_params(const Piece<P>& s, int c) {
  typename Piece<P>::Params t{};
  for (int d = 0; d < P; ++d) t[static_cast<std::size_t>(d)] = s.domain(d)[(c >> d) & 1];
  return t;
}

/// Whether parameter t lies on the boundary of the domain `dom` (exact comparisons: pieces keep
/// the domain's end values exactly).
template <int P>
bool on_boundary(const typename Piece<P>::Params& t, const std::array<std::array<double, 2>, P>& dom) {
  for (int d = 0; d < P; ++d) {
    const auto ud = static_cast<std::size_t>(d);
    if (t[ud] == dom[ud][0] || t[ud] == dom[ud][1]) return true;
  }
  return false;
}

/// The sub-cell analysis of a Bezier piece of det J whose coefficients are all >= -tol times the
/// orientation (the file comment of validity.hpp): for each of its 3^P faces, edges, corners and
/// interior, the largest coefficient of its layer. Returns 0 when every sub-cell off the domain's
/// boundary has one above tol (then det J > 0 there), else 1 and sets `zero_at` to the centre of
/// the first such sub-cell; `degenerate_at` gets the centre of the first boundary sub-cell whose
/// layer is all within tol of 0, if none was known.
template <int P>
int sub_cells(const Piece<P>& s, std::span<const double> c, int orientation, double tol,
              const std::array<std::array<double, 2>, P>& dom, std::optional<typename Piece<P>::Params>& zero_at,
              std::optional<typename Piece<P>::Params>& degenerate_at) {
  int cases = 1;
  for (int d = 0; d < P; ++d) cases *= 3;
  for (int code = 0; code < cases; ++code) {
    // Per direction: 0 the low face, 1 the high face, 2 open (every index).
    std::array<int, P> kind{};
    bool boundary = false;
    typename Piece<P>::Params centre{};
    for (int d = 0, q = code; d < P; ++d, q /= 3) {
      const auto ud = static_cast<std::size_t>(d);
      kind[ud] = q % 3;
      const auto sd = s.domain(d);
      centre[ud] = kind[ud] == 0 ? sd[0] : kind[ud] == 1 ? sd[1] : 0.5 * (sd[0] + sd[1]);
      if ((kind[ud] == 0 && sd[0] == dom[ud][0]) || (kind[ud] == 1 && sd[1] == dom[ud][1])) boundary = true;
    }
    // The layer's largest coefficient (times the orientation).
    double best = -std::numeric_limits<double>::infinity();
    typename Piece<P>::Index i{};
    std::array<int, P> lo{}, hi{};
    for (int d = 0; d < P; ++d) {
      const auto ud = static_cast<std::size_t>(d);
      lo[ud] = kind[ud] == 1 ? s.count(d) - 1 : 0;
      hi[ud] = kind[ud] == 0 ? 0 : s.count(d) - 1;
      i[ud] = lo[ud];
    }
    while (true) {
      best = std::max(best, orientation * c[static_cast<std::size_t>(s.row(i))]);
      int d = 0;
      for (; d < P; ++d) {
        const auto ud = static_cast<std::size_t>(d);
        if (++i[ud] <= hi[ud]) break;
        i[ud] = lo[ud];
      }
      if (d == P) break;
    }
    if (best > tol) continue;
    if (!boundary) {
      zero_at = centre;
      return 1;
    }
    if (!degenerate_at) degenerate_at = centre;
  }
  return 0;
}

template <int P>
ValidityReport<P> check(const Piece<P>& x, const ValidityOptions& opt, int coords) {
  if (x.rational())
    throw Error("a rational " + std::string(P == 3 ? "trivariate" : "surface") +
                ": its Jacobian determinant is not a polynomial; expected a polynomial B-spline to check");
  if (x.dim() < coords)
    throw Error(std::to_string(x.dim()) + " coordinates per control point; expected at least " + std::to_string(coords));
  const Piece<P> det = spline::jacobian_determinant(x);
  ValidityReport<P> r;
  std::array<std::array<double, 2>, P> dom{};
  for (int d = 0; d < P; ++d) dom[static_cast<std::size_t>(d)] = det.domain(d);
  {
    double scale = 0.0;
    for (const double v : det.points()) scale = std::max(scale, std::abs(v));
    r.zero_tolerance = 1e-10 * scale;
  }
  const double tol = r.zero_tolerance;
  r.min_seen = std::numeric_limits<double>::infinity();
  r.max_seen = -r.min_seen;
  r.min_bound = r.min_seen;
  r.max_bound = r.max_seen;

  // The orientation: the sign at the centre of the domain.
  typename Piece<P>::Params centre{};
  for (int d = 0; d < P; ++d) centre[static_cast<std::size_t>(d)] = 0.5 * (det.domain(d)[0] + det.domain(d)[1]);
  const double dc = det.eval(centre)[0];
  r.orientation = dc > 0 ? 1 : dc < 0 ? -1 : 0;
  // A value of the wrong sign or 0 proves the cell invalid, but on the domain's boundary a value
  // within tol of 0 is a degenerate boundary point instead.
  auto seen = [&](double v, const typename Piece<P>::Params& t) {
    r.min_seen = std::min(r.min_seen, v);
    r.max_seen = std::max(r.max_seen, v);
    if (r.orientation != 0 && v * r.orientation <= 0.0 && v * r.orientation >= -tol && on_boundary<P>(t, dom)) return;
    if (!r.invalid_at && (r.orientation == 0 || v * r.orientation <= 0.0)) {
      r.invalid_at = t;
      r.det_at_invalid = v;
    }
  };
  seen(dc, centre);

  std::array<double, P> width{};
  for (int d = 0; d < P; ++d) width[static_cast<std::size_t>(d)] = det.domain(d)[1] - det.domain(d)[0];
  bool undecided = false;
  // Depth first, first halves first: a fixed order, so the first invalid point is deterministic.
  std::vector<Piece<P>> stack;
  {
    auto pieces = spline::bezier_pieces(det);
    std::reverse(pieces.begin(), pieces.end());
    stack = std::move(pieces);
  }
  while (!stack.empty()) {
    Piece<P> s = std::move(stack.back());
    stack.pop_back();
    ++r.pieces;
    const auto c = s.points();
    const auto [lo_it, hi_it] = std::minmax_element(c.begin(), c.end());
    const double lo = *lo_it, hi = *hi_it;
    for (int k = 0; k < (1 << P); ++k) seen(c[static_cast<std::size_t>(s.row(corner_index(s, k)))], corner_params(s, k));
    // Proven invalid: the bounds of this piece and of what is left still count.
    auto bound_rest = [&] {
      r.min_bound = std::min(r.min_bound, lo);
      r.max_bound = std::max(r.max_bound, hi);
      for (const auto& rest : stack) {
        const auto q = rest.points();
        r.min_bound = std::min(r.min_bound, *std::min_element(q.begin(), q.end()));
        r.max_bound = std::max(r.max_bound, *std::max_element(q.begin(), q.end()));
      }
    };
    if (r.invalid_at) {
      bound_rest();
      break;
    }
    const bool decided = r.orientation > 0 ? lo > 0.0 : hi < 0.0;
    if (decided) {
      r.min_bound = std::min(r.min_bound, lo);
      r.max_bound = std::max(r.max_bound, hi);
      continue;
    }
    // Every coefficient of the orientation's sign (within rounding): decided by its sub-cells.
    if (r.orientation != 0 && (r.orientation > 0 ? lo >= -tol : hi <= tol)) {
      std::optional<typename Piece<P>::Params> zero_at;
      if (sub_cells<P>(s, c, r.orientation, tol, dom, zero_at, r.degenerate_at) == 0) {
        r.min_bound = std::min(r.min_bound, lo);
        r.max_bound = std::max(r.max_bound, hi);
        continue;
      }
      // A face, edge or corner inside the domain where det J is 0 (within rounding).
      r.invalid_at = *zero_at;
      r.det_at_invalid = s.eval(*zero_at)[0];
      bound_rest();
      break;
    }
    // Undecided: look at its centre, then split its widest direction (relative to the domain).
    typename Piece<P>::Params mid{};
    int dir = 0;
    double widest = -1.0;
    for (int d = 0; d < P; ++d) {
      const auto dom = s.domain(d);
      mid[static_cast<std::size_t>(d)] = 0.5 * (dom[0] + dom[1]);
      const double rel = (dom[1] - dom[0]) / width[static_cast<std::size_t>(d)];
      if (s.count(d) > 1 && rel > widest) widest = rel, dir = d;
    }
    seen(s.eval(mid)[0], mid);
    if (r.invalid_at) {
      stack.push_back(std::move(s));  // counted in the bounds above
      continue;
    }
    if (widest < opt.min_width || r.pieces + static_cast<int>(stack.size()) >= opt.max_pieces) {
      undecided = true;
      r.min_bound = std::min(r.min_bound, lo);
      r.max_bound = std::max(r.max_bound, hi);
      continue;
    }
    auto [first, second] = spline::split(s, dir, mid[static_cast<std::size_t>(dir)]);
    stack.push_back(std::move(second));
    stack.push_back(std::move(first));
  }
  r.verdict = r.invalid_at ? Validity::invalid
              : undecided  ? Validity::undecided
              : r.degenerate_at ? Validity::degenerate
                               : Validity::valid;
  return r;
}

}  // namespace

const char* validity_name(Validity v) noexcept {
  switch (v) {
    case Validity::valid: return "valid";
    case Validity::invalid: return "invalid";
    case Validity::degenerate: return "degenerate";
    default: return "undecided";
  }
}

namespace {

/// The determinant spline has about 3 x the order per direction and its pieces (3 x order)^P
/// coefficients: the orders are checked before any is built.
template <int P>
void check_orders(const spline::TensorSpline<P>& s) {
  const Limits limits = default_limits();
  for (int d = 0; d < P; ++d)
    check_order(s.knots(d).order(), limits, std::string("validity of a ") + (P == 3 ? "cell" : "surface") +
                                                ", direction " + "uvw"[d]);
}

}  // namespace

ValidityReport<3> check_validity(const spline::Trivariate& cell, const ValidityOptions& options) {
  check_orders(cell);
  return check<3>(cell, options, 3);
}

ValidityReport<2> check_validity(const spline::Surface& surface, const ValidityOptions& options) {
  check_orders(surface);
  return check<2>(surface, options, 2);
}

}  // namespace trivox::geom
