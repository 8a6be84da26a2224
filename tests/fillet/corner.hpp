// The right-angled corner of the fillet tests (floor z = 0, wall x = 2): its faces, rails in
// parameters, sub-regions and the input of the blending surface. Shared by test_fillet_parts.cpp,
// test_vbs_fillet.cpp and test_vrep_fillet.cpp; also the Hermite section's area.
#pragma once
#include <array>
#include <cmath>
#include <vector>

#include "trivox/fillet/blend_surface.hpp"
#include "trivox/fillet/compose.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/refine.hpp"

namespace fillet_test {

/// int_0^1 f(X, Z, X', Z') dt along the cubic Bezier section C_1, C_1 + T_1 / 3, C_2 - T_2 / 3,
/// C_2 in (X, Z) = (x - 2, z) of Alg. 1, Eq. 1 (|T_i| = tau |C_1 - C_2|, legs through the
/// origin along X and Z), with 8 Gauss points: exact for integrands of degree up to 15 in t.
template <class F>
double hermite_integral(double d1, double d2, double tau, F f) {
  const double w = tau * std::hypot(d1, d2);
  const double P[4][2] = {{d1, 0}, {d1 - w / 3, 0}, {0, d2 - w / 3}, {0, d2}};
  const trivox::geom::GaussRule g = trivox::geom::gauss_legendre(8);
  double sum = 0.0;
  for (std::size_t i = 0; i < g.nodes.size(); ++i) {
    const double t = 0.5 * (g.nodes[i] + 1), s = 1 - t;
    const double B[4] = {s * s * s, 3 * t * s * s, 3 * t * t * s, t * t * t};
    const double dB[4] = {-3 * s * s, 3 * s * s - 6 * t * s, 6 * t * s - 3 * t * t, 3 * t * t};
    double X = 0, Z = 0, dX = 0, dZ = 0;
    for (int j = 0; j < 4; ++j) X += B[j] * P[j][0], Z += B[j] * P[j][1], dX += dB[j] * P[j][0], dZ += dB[j] * P[j][1];
    sum += 0.5 * g.weights[i] * f(X, Z, dX, dZ);
  }
  return sum;
}

/// Area of the region between the legs and the section, by Green's theorem (1/2) oint (X Z' - Z X').
inline double hermite_area(double d1, double d2, double tau) {
  return hermite_integral(d1, d2, tau, [](double X, double Z, double dX, double dZ) { return 0.5 * (X * dZ - Z * dX); });
}

using trivox::spline::Curve;
using trivox::spline::KnotVector;
using trivox::spline::Surface;
namespace fillet = trivox::fillet;
namespace spline = trivox::spline;

/// A trilinear box cell [lo, hi] with one property value.
inline trivox::spline::Trivariate box_cell(std::array<double, 3> lo, std::array<double, 3> hi, double value) {
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) pts.insert(pts.end(), {i ? hi[0] : lo[0], j ? hi[1] : lo[1], k ? hi[2] : lo[2], value});
  const auto kv = KnotVector::bezier(2);
  return trivox::spline::Trivariate({kv, kv, kv}, 4, pts);
}

/// A bilinear patch through four corners (u fastest), in R^dim.
inline Surface patch(const std::vector<double>& c00, const std::vector<double>& c10, const std::vector<double>& c01,
                     const std::vector<double>& c11) {
  std::vector<double> pts;
  for (const auto* c : {&c00, &c10, &c01, &c11}) pts.insert(pts.end(), c->begin(), c->end());
  return Surface({KnotVector::bezier(2), KnotVector::bezier(2)}, static_cast<int>(c00.size()), pts);
}

inline Curve line(double u0, double v0, double u1, double v1) {
  // Cubic, so it is in the same space as the rails of real fillets.
  Curve c({KnotVector::bezier(2)}, 2, {u0, v0, u1, v1});
  return spline::elevate(c, 0, 2);
}

/// The right-angled corner: floor z = 0 (x in [2, 6], y in [0, 4]) outside a wall x <= 2 whose
/// face x = 2 spans z in [0, 4]. C is the line x = 2, z = 0, y = 4t; rail 1 at x = 2 + d1 on the
/// floor, rail 2 at z = d2 on the wall. Properties: one per point, linear on each face.
struct Corner {
  double d1 = 1.0, d2 = 0.5;
  // Floor (u, v) -> (2 + 4u, 4v, 0), property 10 + u; wall (u, v) -> (2, 4u, 4v), property 20 + v.
  Surface floor_ = patch({2, 0, 0, 10}, {6, 0, 0, 11}, {2, 4, 0, 10}, {6, 4, 0, 11});
  Surface wall = patch({2, 0, 0, 20}, {2, 4, 0, 20}, {2, 0, 4, 21}, {2, 4, 4, 21});
  // In parameters: C on the floor is u = 0, v = t; rail 1 is u = d1 / 4. On the wall C is v = 0,
  // u = t; rail 2 is v = d2 / 4.
  Curve base1 = line(0, 0, 0, 1), rail1 = line(d1 / 4, 0, d1 / 4, 1);
  Curve base2 = line(0, 0, 1, 0), rail2 = line(0, d2 / 4, 1, d2 / 4);

  Surface sub1() const { return fillet::subregion(floor_, rail1, base1); }
  Surface sub2() const { return fillet::subregion(wall, base2, rail2); }
  fillet::BlendInput input(const Surface& s1, const Surface& s2) const {
    fillet::BlendInput in;
    in.faces = {&floor_, &wall};
    in.rail_uv = {rail1, rail2};
    in.rail = {spline::iso(s1, 1, 0.0), spline::iso(s2, 1, 1.0)};
    in.center = spline::iso(s1, 1, 1.0);
    return in;
  }
};

}  // namespace fillet_test
