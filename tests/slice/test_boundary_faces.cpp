// Trimmed boundary faces of Boolean pieces (slice/boundary_faces.hpp). Truths, for the box
// A = [0, 2]^2 x [0, 1] and the box B = [0.5, 1.5]^2 x [-1, 2] passing through it along z:
// - A - B is A with a square through-hole: its top and bottom faces are 4 - 1 = 3 each, its
//   four sides 2 each, the hole's four walls 1 x 1 each: 18 in all;
// - A n B is the unit cube [0.5, 1.5]^2 x [0, 1]: 6;
// - the boundary of A - B and of A n B together are the boundary of A plus the part of B's
//   boundary inside A counted twice (once as the hole's wall, once as the cube's sides):
//   area(d(A - B)) + area(d(A n B)) = area(dA) + 2 area(dB n A) = 16 + 2 x 4.
// Planar faces: the areas are polygon areas, exact to 1e-8.
// A box minus a one-cell cylinder C whose cross-section is bounded by four cubic Bezier arcs
// (a Coons patch of them, so the cross-section is known exactly): the box's top keeps
// 4 - A_c, A_c by Green's theorem on the arcs, the hole's wall is the arcs' length L_c times the
// box's height, and the same identity holds with dC n A of area L_c. The top's hole is bounded
// by marched intersection curves (within the intersection tolerance of the arcs), so it agrees
// to about 1e-10, not to rounding.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "trivox/error.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/slice/boundary_faces.hpp"
#include "trivox/vmodel/boolean.hpp"

using namespace trivox;
using spline::KnotVector;
using vmodel::BooleanOp;
using vmodel::VModel;

namespace {

VModel box(const std::string& name, std::array<double, 3> lo, std::array<double, 3> hi) {
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) pts.insert(pts.end(), {i ? hi[0] : lo[0], j ? hi[1] : lo[1], k ? hi[2] : lo[2], 0.5});
  const KnotVector b = KnotVector::bezier(2);
  VModel m;
  m.properties = {"r"};
  m.cells.push_back({name, spline::Trivariate({b, b, b}, 4, pts)});
  return m;
}

double model_boundary(const VModel& m, std::vector<slice::BoundaryFace>* all = nullptr) {
  double a = 0;
  for (int c = 0; c < static_cast<int>(m.cells.size()); ++c) {
    auto f = slice::boundary_faces(m, c);
    a += slice::boundary_area(f);
    if (all) all->insert(all->end(), f.begin(), f.end());
  }
  return a;
}

using P2 = std::array<double, 2>;
const double kPi = std::acos(-1.0);

/// The cubic Bezier arc of radius r from angle a0 to a0 + 90 degrees (the usual approximation
/// of a quarter circle, k = 4/3 tan(pi/8)), reversed when `rev`.
std::array<P2, 4> arc(double r, double a0, bool rev) {
  const double a1 = a0 + kPi / 2, k = 4.0 / 3.0 * std::tan(kPi / 8);
  std::array<P2, 4> c{P2{r * std::cos(a0), r * std::sin(a0)},
                      P2{r * std::cos(a0) - k * r * std::sin(a0), r * std::sin(a0) + k * r * std::cos(a0)},
                      P2{r * std::cos(a1) + k * r * std::sin(a1), r * std::sin(a1) - k * r * std::cos(a1)},
                      P2{r * std::cos(a1), r * std::sin(a1)}};
  if (rev) std::swap(c[0], c[3]), std::swap(c[1], c[2]);
  return c;
}

/// One polynomial cell whose cross-section is the Coons patch (bilinearly blended, Bezier
/// bicubic) of the four arcs: its lateral faces are the four arcs extruded from z0 to z1, so its
/// cross-section is exactly the region inside the four arcs.
VModel coons_cylinder(double r, double z0, double z1) {
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
  VModel m;
  m.properties = {"r"};
  m.cells.push_back({"C", spline::Trivariate({KnotVector::bezier(4), KnotVector::bezier(4), KnotVector::bezier(2)}, 4, pts)});
  return m;
}

/// The area enclosed by the four arcs (Green's theorem, 1/2 int x y' - y x', exact for the
/// polynomial integrand) and their length (int |c'|, 64 Gauss points per arc: the integrand is
/// smooth and nearly constant, so the rule is exact to rounding).
std::pair<double, double> arcs_area_length(double r) {
  const auto g = geom::gauss_legendre(64);
  double area = 0, length = 0;
  for (int q = 0; q < 4; ++q) {
    const auto c = arc(r, kPi / 4 + q * kPi / 2, false);
    for (std::size_t n = 0; n < g.nodes.size(); ++n) {
      const double t = 0.5 * (1 + g.nodes[n]), w = 0.5 * g.weights[n], s = 1 - t;
      double x = 0, y = 0, dx = 0, dy = 0;
      const double b[4] = {s * s * s, 3 * s * s * t, 3 * s * t * t, t * t * t};
      const double db[4] = {-3 * s * s, 3 * s * s - 6 * s * t, 6 * s * t - 3 * t * t, 3 * t * t};
      for (int i = 0; i < 4; ++i) {
        x += b[i] * c[i][0], y += b[i] * c[i][1], dx += db[i] * c[i][0], dy += db[i] * c[i][1];
      }
      area += w * 0.5 * (x * dy - y * dx);
      length += w * std::hypot(dx, dy);
    }
  }
  return {area, length};
}

}  // namespace

TEST_CASE("boundary faces of a box minus a cylinder through it", "[boundary_faces]") {
  // A = [-1, 1]^2 x [0, 1]; the cylinder cell C (radius 0.5 about the z axis, z in [-1, 2]) has
  // the cross-section bounded by four cubic arcs, of area A_c and perimeter L_c computed from
  // the arcs themselves: top = 4 - A_c, hole wall = L_c x 1, and the whole boundary of A - C is
  // 2 (4 - A_c) + 4 x 2 + L_c; A n C is the cylinder of height 1: 2 A_c + L_c.
  const VModel A = box("A", {-1, -1, 0}, {1, 1, 1}), C = coons_cylinder(0.5, -1, 2);
  const auto [ac, lc] = arcs_area_length(0.5);
  REQUIRE(std::abs(ac - kPi * 0.25) < 1e-3);
  const VModel D = vmodel::boolean(A, C, BooleanOp::subtraction);
  std::vector<slice::BoundaryFace> faces;
  const double d = model_boundary(D, &faces);
  double top = 0, wall = 0;
  for (const auto& f : faces) {
    if (f.source == -1 && f.face == spline::Face::w1) top += f.area;
    if (f.source >= 0) wall += f.area;
  }
  std::printf("box minus cylinder: top %.15g (expected %.15g), wall %.15g (expected %.15g), boundary %.15g (expected %.15g)\n",
              top, 4 - ac, wall, lc, d, 2 * (4 - ac) + 8 + lc);
  CHECK(std::abs(top - (4 - ac)) <= 1e-8 * 4);
  CHECK(std::abs(wall - lc) <= 1e-8 * lc);
  CHECK(std::abs(d - (2 * (4 - ac) + 8 + lc)) <= 1e-8 * d);
  const VModel I = vmodel::boolean(A, C, BooleanOp::intersection);
  const double i = model_boundary(I);
  std::printf("box and cylinder: boundary %.15g (expected %.15g)\n", i, 2 * ac + lc);
  CHECK(std::abs(i - (2 * ac + lc)) <= 1e-8 * i);
  // d(A - C) + d(A n C) = dA + 2 (dC n A).
  CHECK(std::abs(d + i - (16 + 2 * lc)) <= 1e-8 * (d + i));
}

TEST_CASE("boundary faces of a box minus a box through it", "[boundary_faces]") {
  const VModel A = box("A", {0, 0, 0}, {2, 2, 1}), B = box("B", {0.5, 0.5, -1}, {1.5, 1.5, 2});
  const VModel D = vmodel::boolean(A, B, BooleanOp::subtraction);
  std::vector<slice::BoundaryFace> faces;
  const double d = model_boundary(D, &faces);
  std::printf("box minus box: boundary area %.15g (expected 18), %zu faces\n", d, faces.size());
  CHECK(std::abs(d - 18) <= 1e-8 * 18);
  // The top face (z = 1) of A: 4 - 1.
  int tops = 0;
  for (const auto& f : faces)
    if (f.source == -1 && f.face == spline::Face::w1) {
      ++tops;
      CHECK(std::abs(f.area - 3) <= 1e-8 * 3);
    }
  CHECK(tops == 1);
  // The hole's walls: faces of B (source >= 0), 1 each.
  double walls = 0;
  for (const auto& f : faces)
    if (f.source >= 0) walls += f.area;
  CHECK(std::abs(walls - 4) <= 1e-8 * 4);

  const VModel I = vmodel::boolean(A, B, BooleanOp::intersection);
  const double i = model_boundary(I);
  std::printf("box and box: boundary area %.15g (expected 6)\n", i);
  CHECK(std::abs(i - 6) <= 1e-8 * 6);
  CHECK(std::abs(d + i - (16 + 2 * 4)) <= 1e-8 * 24);
}

TEST_CASE("boundary faces refuse a cell out of range", "[boundary_faces]") {
  const VModel A = box("A", {0, 0, 0}, {2, 2, 1});
  CHECK_THROWS_AS(slice::boundary_faces(A, 1), Error);
  // A plain cell's boundary is its six faces.
  CHECK(std::abs(slice::boundary_area(slice::boundary_faces(A, 0)) - 16) <= 1e-8 * 16);
}
