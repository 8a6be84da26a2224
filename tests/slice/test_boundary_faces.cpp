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
#include "boundary_fixtures.hpp"

using namespace trivox;
using vmodel::BooleanOp;
using vmodel::VModel;

using test::arcs_area_length;
using test::box;
using test::coons_cylinder;
using test::kPi;

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
  const double d = test::cells_boundary_area(D, &faces);
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
  const double i = test::cells_boundary_area(I);
  std::printf("box and cylinder: boundary %.15g (expected %.15g)\n", i, 2 * ac + lc);
  CHECK(std::abs(i - (2 * ac + lc)) <= 1e-8 * i);
  // d(A - C) + d(A n C) = dA + 2 (dC n A).
  CHECK(std::abs(d + i - (16 + 2 * lc)) <= 1e-8 * (d + i));
}

TEST_CASE("boundary faces of a box minus a box through it", "[boundary_faces]") {
  const VModel A = box("A", {0, 0, 0}, {2, 2, 1}), B = box("B", {0.5, 0.5, -1}, {1.5, 1.5, 2});
  const VModel D = vmodel::boolean(A, B, BooleanOp::subtraction);
  std::vector<slice::BoundaryFace> faces;
  const double d = test::cells_boundary_area(D, &faces);
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
  const double i = test::cells_boundary_area(I);
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
