// Internal to the fillet module: small vector arithmetic in R^3, number formatting for messages,
// the knot halving the adaptive fits share, and det J at a point.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "trivox/spline/knot_vector.hpp"
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

}  // namespace trivox::fillet::detail
