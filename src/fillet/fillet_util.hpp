// Internal to the fillet module: small vector arithmetic in R^3, number formatting for messages,
// the knot halving the adaptive fits share, det J at a point, and the rows, layers, splits and
// projections of the volumetric constructions (VBS, Alg. 3; V-rep, Alg. 6).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "trivox/construct/constructors.hpp"
#include "trivox/error.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/knot_vector.hpp"
#include "trivox/spline/refine.hpp"
#include "trivox/spline/tensor_spline.hpp"

namespace trivox::fillet::detail {

using Vec = std::array<double, 3>;

inline std::string num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

inline Vec sub(const Vec& a, const Vec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
/// a + s b
inline Vec axpy(const Vec& a, double s, const Vec& b) { return {a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]}; }
inline Vec scale(const Vec& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Vec& a) { return std::sqrt(dot(a, a)); }
/// The first three values (xyz) of a point.
inline Vec xyz(const double* p) { return {p[0], p[1], p[2]}; }
inline Vec xyz(const std::vector<double>& p) { return {p[0], p[1], p[2]}; }
/// a / |a| (a itself when it is zero).
inline Vec unit(const Vec& a) {
  const double n = norm(a);
  return n > 0.0 ? Vec{a[0] / n, a[1] / n, a[2] / n} : a;
}
/// Unit normal of s (xyz) at (u, v); zero where s is singular. `across`: dS/dv there.
inline Vec unit_normal(const spline::Surface& s, double u, double v, Vec* across = nullptr) {
  const auto d = s.eval_derivatives({u, v}, 1);
  const std::size_t k = static_cast<std::size_t>(s.dim());
  if (across) *across = xyz(d.data() + 2 * k);
  return unit(cross(xyz(d.data() + k), xyz(d.data() + 2 * k)));
}

/// The same knots with every non-empty span split at its middle (simple new knots).
inline spline::KnotVector halved(const spline::KnotVector& k) {
  std::vector<double> all = k.knots();
  const auto br = k.breakpoints();
  for (std::size_t i = 0; i + 1 < br.size(); ++i) all.push_back(0.5 * (br[i].value + br[i + 1].value));
  std::sort(all.begin(), all.end());
  return spline::KnotVector(k.order(), all);
}

/// det[dX/du, dX/dv, dX/dw] of a trivariate's xyz at t.
inline double jacobian_at(const spline::Trivariate& s, const std::array<double, 3>& t) {
  const auto d = s.eval_derivatives(t, 1);
  const std::size_t k = static_cast<std::size_t>(s.dim());
  return dot(xyz(d.data() + k), cross(xyz(d.data() + 2 * k), xyz(d.data() + 3 * k)));
}

// ---- rows, layers and projections shared by the VBS (Alg. 3) and V-rep (Alg. 6) fillets ----

/// Row j across (direction 1) of s: the curve along u whose control points are s's P_{m, j}.
inline spline::Curve row(const spline::Surface& s, int j) {
  std::vector<double> pts;
  for (int m = 0; m < s.count(0); ++m) {
    const auto p = s.point(s.row({m, j}));
    pts.insert(pts.end(), p.begin(), p.end());
  }
  return spline::Curve({s.knots(0)}, s.dim(), std::move(pts));
}

/// Overwrites coordinates [0, coords) of row j of s with c's control points (same u space).
inline void set_row(spline::Surface& s, int j, const spline::Curve& c, int coords) {
  for (int m = 0; m < s.count(0); ++m) {
    auto p = s.point(s.row({m, j}));
    const auto q = c.point(m);
    std::copy(q.begin(), q.begin() + coords, p.begin());
  }
}

inline double distance3(std::span<const double> a, std::span<const double> b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

/// Largest xyz distance between the control points of two curves in one space.
inline double curve_gap(const spline::Curve& a, const spline::Curve& b) {
  double g = 0.0;
  for (int m = 0; m < a.size(); ++m) g = std::max(g, distance3(a.point(m), b.point(m)));
  return g;
}

/// Eq. A.1: the parameter v in [0, 1] of the orthogonal projection of p (xyz) on the curve c(v):
/// <p - c(v), c'(v)> = 0 at the nearest of 129 samples, refined by Newton's method.
inline double project(const spline::Curve& c, const std::array<double, 3>& p) {
  const auto [lo, hi] = c.domain(0);
  const auto dist2 = [&](double v) {
    const auto x = c.eval({v});
    return (x[0] - p[0]) * (x[0] - p[0]) + (x[1] - p[1]) * (x[1] - p[1]) + (x[2] - p[2]) * (x[2] - p[2]);
  };
  double v = lo, best = dist2(lo);
  for (int i = 1; i <= 128; ++i) {
    const double t = lo + (hi - lo) * i / 128.0;
    const double d = dist2(t);
    if (d < best) best = d, v = t;
  }
  const std::size_t k = static_cast<std::size_t>(c.dim());
  for (int it = 0; it < 60; ++it) {
    const auto d = c.eval_derivatives({v}, 2);
    double f = 0.0, fp = 0.0;
    for (std::size_t j = 0; j < 3; ++j) {
      const double e = d[j] - p[j];
      f += e * d[k + j];
      fp += d[k + j] * d[k + j] + e * d[2 * k + j];
    }
    if (!(fp > 0.0)) break;
    const double next = std::clamp(v - f / fp, lo, hi);
    const double step = std::abs(next - v);
    v = next;
    if (step <= 1e-15 * (hi - lo)) break;
  }
  return (v - lo) / (hi - lo);
}

inline std::array<double, 3> xyz_at(const spline::Curve& c, double t) {
  const auto x = c.eval({t});
  return {x[0], x[1], x[2]};
}

/// Writes face f's control net into the boundary layer of t where direction dir has index
/// `index` (f's parameters are t's two other directions in increasing order, in t's spaces).
inline void set_layer(spline::Trivariate& t, int dir, int index, const spline::Surface& f, const char* what) {
  const int a = dir == 0 ? 1 : 0, b = dir == 2 ? 1 : 2;
  if (f.knots(0) != t.knots(a) || f.knots(1) != t.knots(b))
    throw Error(std::string(what) + ": a face is not in its cell's function space (internal)", ErrorKind::failed);
  for (int j = 0; j < f.count(1); ++j)
    for (int i = 0; i < f.count(0); ++i) {
      std::array<int, 3> idx{};
      idx[static_cast<std::size_t>(dir)] = index;
      idx[static_cast<std::size_t>(a)] = i;
      idx[static_cast<std::size_t>(b)] = j;
      const auto q = f.point(f.row({i, j}));
      auto p = t.point(t.row(idx));
      std::copy(q.begin(), q.end(), p.begin());
    }
}

/// Knots closer than this (on [0, 1]) are one knot: the pieces' spaces come from restrictions,
/// normalisations and reversals, which give the same value in different roundings.
inline constexpr double knot_merge = 1e-11;

/// The splines with their interior knots in direction `dir` (all on [0, 1]) that lie within
/// `tol` of each other moved onto one value (the smallest of the cluster), so the union of their
/// spaces has no sliver spans. Moving a knot by d changes a spline by O(d) times its
/// control-point differences: rounding.
template <int P>
void merge_close_knots(std::vector<spline::TensorSpline<P>>& pieces, int dir = P - 1, double tol = knot_merge) {
  std::vector<double> all;
  for (const auto& s : pieces) {
    const auto& kv = s.knots(dir);
    for (int i = kv.order(); i < kv.size(); ++i) all.push_back(kv[i]);
  }
  std::sort(all.begin(), all.end());
  const auto representative = [&](double x) {
    // The first value of x's cluster: walk down while the gaps stay within tol.
    auto it = std::lower_bound(all.begin(), all.end(), x);
    while (it != all.begin() && *it - *(it - 1) <= tol) --it;
    return *it;
  };
  for (auto& s : pieces) {
    const auto& kv = s.knots(dir);
    std::vector<double> k = kv.knots();
    bool moved = false;
    for (int i = kv.order(); i < kv.size(); ++i) {
      const double r = representative(k[static_cast<std::size_t>(i)]);
      moved = moved || r != k[static_cast<std::size_t>(i)];
      k[static_cast<std::size_t>(i)] = r;
    }
    if (moved) {
      auto knots = s.knot_vectors();
      knots[static_cast<std::size_t>(dir)] = spline::KnotVector(kv.order(), std::move(k));
      s = spline::TensorSpline<P>(std::move(knots), s.dim(), std::vector<double>(s.points().begin(), s.points().end()));
    }
  }
}

/// The pieces of s across (direction 1) on [0, t] and [t, 1], each normalized to [0, 1]^2. A t
/// within knot_merge of one of s's knots is moved onto it (no sliver span).
inline std::pair<spline::Surface, spline::Surface> split_across(const spline::Surface& s, double& t) {
  for (const double x : s.knots(1).knots())
    if (std::abs(x - t) <= knot_merge) t = x;
  auto [a, b] = spline::split(s, 1, t);
  return {construct::normalized(a), construct::normalized(b)};
}

/// Parameters at which det J is sampled along a cell's u (along C): the midpoint of every
/// non-empty knot span, or 16 uniform midpoints when there are fewer spans.
inline std::vector<double> u_samples(const spline::Trivariate& t) {
  const auto br = t.knots(0).breakpoints();
  std::vector<double> out;
  if (br.size() >= 17) {
    for (std::size_t i = 0; i + 1 < br.size(); ++i) out.push_back(0.5 * (br[i].value + br[i + 1].value));
  } else {
    const auto d = t.domain(0);
    for (int a = 0; a < 16; ++a) out.push_back(d[0] + (d[1] - d[0]) * (a + 0.5) / 16);
  }
  return out;
}

/// det J sampled inside a cell (not bounded: fillet cells' det J vanishes on their rails, Masalha
/// et al. 2021 Sec. 9, where geom::check_validity chases it): at u_samples along u times n1 x n2
/// midpoints across. Returns {min, max}.
inline std::array<double, 2> sampled_jacobian(const spline::Trivariate& h, int n1 = 6, int n2 = 4) {
  std::array<double, 2> range{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  const auto dv = h.domain(1), dw = h.domain(2);
  for (const double u : u_samples(h))
    for (int b = 0; b < n1; ++b)
      for (int c = 0; c < n2; ++c) {
        const double det = jacobian_at(h, {u, dv[0] + (dv[1] - dv[0]) * (b + 0.5) / n1, dw[0] + (dw[1] - dw[0]) * (c + 0.5) / n2});
        range[0] = std::min(range[0], det);
        range[1] = std::max(range[1], det);
      }
  return range;
}

/// The signed volume int det J of a polynomial cell by the divergence theorem: det DX =
/// (1/3) sum_i d_i((X - c) . (X_j x X_k)) over cyclic (i, j, k) (the cyclic sum of
/// d_i (X_j x X_k) vanishes), so the volume is a third of the flux of X - c through the six
/// faces, for any c (c: a control point, against cancellation). On a face of degrees (p, q) the
/// integrand has degrees (3p - 1, 3q - 1): ceil(3p / 2) x ceil(3q / 2) Gauss points per element
/// integrate it exactly, as geom::volume does det J, at the cost of six surfaces instead of a
/// volume (the VBS cells have a thousand spans along C and ten across).
inline double boundary_volume(const spline::Trivariate& t) {
  const std::size_t k = static_cast<std::size_t>(t.dim());
  const auto c0 = t.point(0);
  const Vec c{c0[0], c0[1], c0[2]};
  double total = 0.0;
  std::vector<double> d(3 * k);
  for (const spline::Face face : spline::all_faces) {
    const int dir = static_cast<int>(face) / 2;
    const bool at_max = static_cast<int>(face) % 2 == 1;
    // boundary_face's parameters are the other two directions in increasing order: for v that
    // is (u, w), and X_u x X_w = -(X_w x X_u), the cyclic order.
    const double sign = (at_max ? 1.0 : -1.0) * (dir == 1 ? -1.0 : 1.0);
    const spline::Surface f = spline::boundary_face(t, face);
    std::array<geom::GaussRule, 2> rule;
    std::array<std::vector<double>, 2> br;
    for (int e = 0; e < 2; ++e) {
      rule[static_cast<std::size_t>(e)] = geom::gauss_legendre(std::max(1, (3 * f.knots(e).degree() + 1) / 2));
      for (const auto& b : f.knots(e).breakpoints()) br[static_cast<std::size_t>(e)].push_back(b.value);
    }
    double flux = 0.0;
    for (std::size_t eb = 0; eb + 1 < br[1].size(); ++eb)
      for (std::size_t ea = 0; ea + 1 < br[0].size(); ++ea) {
        const double ha = 0.5 * (br[0][ea + 1] - br[0][ea]), hb = 0.5 * (br[1][eb + 1] - br[1][eb]);
        double element = 0.0;
        for (std::size_t j = 0; j < rule[1].nodes.size(); ++j)
          for (std::size_t i = 0; i < rule[0].nodes.size(); ++i) {
            f.eval_derivatives({br[0][ea] + ha * (1 + rule[0].nodes[i]), br[1][eb] + hb * (1 + rule[1].nodes[j])}, 1,
                               d.data());
            element += rule[0].weights[i] * rule[1].weights[j] *
                       dot(sub(xyz(d.data()), c), cross(xyz(d.data() + k), xyz(d.data() + 2 * k)));
          }
        flux += element * ha * hb;
      }
    total += sign * flux;
  }
  return total / 3.0;
}

}  // namespace trivox::fillet::detail
