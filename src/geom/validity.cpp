#include "trivox/geom/validity.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "trivox/error.hpp"
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

template <int P>
ValidityReport<P> check(const Piece<P>& x, const ValidityOptions& opt, int coords) {
  if (x.rational())
    throw Error("a rational " + std::string(P == 3 ? "trivariate" : "surface") +
                ": its Jacobian determinant is not a polynomial; expected a polynomial B-spline to check");
  if (x.dim() < coords)
    throw Error(std::to_string(x.dim()) + " coordinates per control point; expected at least " + std::to_string(coords));
  const Piece<P> det = spline::jacobian_determinant(x);
  ValidityReport<P> r;
  r.min_seen = std::numeric_limits<double>::infinity();
  r.max_seen = -r.min_seen;
  r.min_bound = r.min_seen;
  r.max_bound = r.max_seen;

  // The orientation: the sign at the centre of the domain.
  typename Piece<P>::Params centre{};
  for (int d = 0; d < P; ++d) centre[static_cast<std::size_t>(d)] = 0.5 * (det.domain(d)[0] + det.domain(d)[1]);
  const double dc = det.eval(centre)[0];
  r.orientation = dc > 0 ? 1 : dc < 0 ? -1 : 0;
  auto seen = [&](double v, const typename Piece<P>::Params& t) {
    r.min_seen = std::min(r.min_seen, v);
    r.max_seen = std::max(r.max_seen, v);
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
    if (r.invalid_at) {
      // Proven invalid: the bounds of what is left still count.
      r.min_bound = std::min(r.min_bound, lo);
      r.max_bound = std::max(r.max_bound, hi);
      for (const auto& rest : stack) {
        const auto q = rest.points();
        r.min_bound = std::min(r.min_bound, *std::min_element(q.begin(), q.end()));
        r.max_bound = std::max(r.max_bound, *std::max_element(q.begin(), q.end()));
      }
      break;
    }
    const bool decided = r.orientation > 0 ? lo > 0.0 : hi < 0.0;
    if (decided) {
      r.min_bound = std::min(r.min_bound, lo);
      r.max_bound = std::max(r.max_bound, hi);
      continue;
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
  r.verdict = r.invalid_at ? Validity::invalid : undecided ? Validity::undecided : Validity::valid;
  return r;
}

}  // namespace

const char* validity_name(Validity v) noexcept {
  switch (v) {
    case Validity::valid: return "valid";
    case Validity::invalid: return "invalid";
    default: return "undecided";
  }
}

ValidityReport<3> check_validity(const spline::Trivariate& cell, const ValidityOptions& options) {
  return check<3>(cell, options, 3);
}

ValidityReport<2> check_validity(const spline::Surface& surface, const ValidityOptions& options) {
  return check<2>(surface, options, 2);
}

}  // namespace trivox::geom
