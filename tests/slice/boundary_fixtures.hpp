// Cells with known boundaries for the tests of Boolean pieces' faces and measures
// (slice/boundary_faces.hpp, slice/piece_measures.hpp): axis-aligned boxes, a one-cell cylinder
// whose cross-section is bounded by four cubic Bezier arcs (so its area and perimeter are known
// independently, by Green's theorem on the arcs), and the boundary of every cell of a model.
#pragma once
#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "trivox/geom/quadrature.hpp"
#include "trivox/slice/boundary_faces.hpp"
#include "trivox/spline/tensor_spline.hpp"
#include "trivox/vmodel/vmodel.hpp"

namespace trivox::test {

/// The box [lo, hi] as one trilinear cell with one property "r" = 0.5; `mirror` reverses u
/// (a left-handed parametrisation, det J < 0).
inline vmodel::VModel box(const std::string& name, std::array<double, 3> lo, std::array<double, 3> hi,
                          bool mirror = false) {
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        const bool x = mirror ? !i : i;
        pts.insert(pts.end(), {x ? hi[0] : lo[0], j ? hi[1] : lo[1], k ? hi[2] : lo[2], 0.5});
      }
  const auto b = spline::KnotVector::bezier(2);
  vmodel::VModel m;
  m.properties = {"r"};
  m.cells.push_back({name, spline::Trivariate({b, b, b}, 4, pts)});
  return m;
}

using P2 = std::array<double, 2>;
inline const double kPi = std::acos(-1.0);

/// The cubic Bezier arc of radius r from angle a0 to a0 + 90 degrees (k = 4/3 tan(pi/8): its
/// ends and its middle lie on the circle), reversed when `rev`.
inline std::array<P2, 4> arc(double r, double a0, bool rev) {
  const double a1 = a0 + kPi / 2, k = 4.0 / 3.0 * std::tan(kPi / 8);
  std::array<P2, 4> c{P2{r * std::cos(a0), r * std::sin(a0)},
                      P2{r * std::cos(a0) - k * r * std::sin(a0), r * std::sin(a0) + k * r * std::cos(a0)},
                      P2{r * std::cos(a1) + k * r * std::sin(a1), r * std::sin(a1) - k * r * std::cos(a1)},
                      P2{r * std::cos(a1), r * std::sin(a1)}};
  if (rev) std::swap(c[0], c[3]), std::swap(c[1], c[2]);
  return c;
}

/// One polynomial cell "C" whose cross-section is the Coons patch (bilinearly blended, Bezier
/// bicubic) of the four arcs, their middles at 0, 90, 180 and 270 degrees, extruded from z0 to
/// z1: its lateral faces are the arcs extruded, so its cross-section is exactly the region
/// inside them.
inline vmodel::VModel coons_cylinder(double r, double z0, double z1) {
  const auto bottom = arc(r, 5 * kPi / 4, false), right = arc(r, 7 * kPi / 4, false);
  const auto top = arc(r, kPi / 4, true), left = arc(r, 3 * kPi / 4, true);
  std::array<std::array<P2, 4>, 4> P{};  // P[i][j], i along u, j along v
  for (int i = 0; i < 4; ++i) P[i][0] = bottom[i], P[i][3] = top[i];
  for (int j = 0; j < 4; ++j) P[0][j] = left[j], P[3][j] = right[j];
  for (int i = 1; i < 3; ++i)
    for (int j = 1; j < 3; ++j)
      for (int d = 0; d < 2; ++d) {
        const double s = i / 3.0, t = j / 3.0;
        P[i][j][d] = (1 - s) * P[0][j][d] + s * P[3][j][d] + (1 - t) * P[i][0][d] + t * P[i][3][d] -
                     ((1 - s) * (1 - t) * P[0][0][d] + s * (1 - t) * P[3][0][d] + (1 - s) * t * P[0][3][d] +
                      s * t * P[3][3][d]);
      }
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) pts.insert(pts.end(), {P[i][j][0], P[i][j][1], k ? z1 : z0, 0.5});
  vmodel::VModel m;
  m.properties = {"r"};
  using spline::KnotVector;
  m.cells.push_back({"C", spline::Trivariate({KnotVector::bezier(4), KnotVector::bezier(4), KnotVector::bezier(2)}, 4, pts)});
  return m;
}

/// The area enclosed by the four arcs (Green's theorem, 1/2 int x y' - y x', a polynomial of
/// degree 5 that the rule integrates exactly) and their length (int |c'|: smooth and nearly
/// constant, so 64 Gauss points per arc are exact to rounding).
inline std::pair<double, double> arcs_area_length(double r) {
  const auto g = geom::gauss_legendre(64);
  double area = 0, length = 0;
  for (int q = 0; q < 4; ++q) {
    const auto c = arc(r, kPi / 4 + q * kPi / 2, false);
    for (std::size_t n = 0; n < g.nodes.size(); ++n) {
      const double t = 0.5 * (1 + g.nodes[n]), w = 0.5 * g.weights[n], s = 1 - t;
      double x = 0, y = 0, dx = 0, dy = 0;
      const double b[4] = {s * s * s, 3 * s * s * t, 3 * s * t * t, t * t * t};
      const double db[4] = {-3 * s * s, 3 * s * s - 6 * s * t, 6 * s * t - 3 * t * t, 3 * t * t};
      for (int i = 0; i < 4; ++i) x += b[i] * c[i][0], y += b[i] * c[i][1], dx += db[i] * c[i][0], dy += db[i] * c[i][1];
      area += w * 0.5 * (x * dy - y * dx);
      length += w * std::hypot(dx, dy);
    }
  }
  return {area, length};
}

/// The summed boundary area of every cell of `m` (slice::boundary_faces), the faces appended to
/// `all` when given.
inline double cells_boundary_area(const vmodel::VModel& m, std::vector<slice::BoundaryFace>* all = nullptr) {
  double a = 0;
  for (int c = 0; c < static_cast<int>(m.cells.size()); ++c) {
    auto f = slice::boundary_faces(m, c);
    a += slice::boundary_area(f);
    if (all) all->insert(all->end(), f.begin(), f.end());
  }
  return a;
}

}  // namespace trivox::test
