// Exact measures of Boolean pieces from their trimmed boundaries (slice/piece_measures.hpp) and
// the glued faces of a model (slice/model_boundary.hpp). Truths:
// - box minus box: volumes, centroids and bounding boxes of axis-aligned boxes (planar faces
//   cut along straight lines: exact to rounding);
// - box minus a one-cell cylinder C whose cross-section is bounded by four cubic Bezier arcs (a
//   Coons patch of them): vol(C n A) = A_c x height with A_c by Green's theorem on the arcs, so
//   vol(A - C) = vol(A) - A_c h; the hole's boundary is marched intersection curves, so these
//   agree within the intersection tolerance, not to rounding. Each arc is symmetric about its
//   middle, where it meets the circle, so the cross-section's extreme x and y are +-r exactly;
// - inclusion-exclusion: vol(A - B) + vol(A n B) = vol(A), and vol(A u B) + vol(A n B) =
//   vol(A) + vol(B) with vol(A u B) the sum over the union's pieces;
// - a cylinder wholly inside a box (no intersection curve: the cylinder's faces are the
//   cavity's walls whole): vol(A - C) = vol(A) - vol(C);
// - a left-handed box (det J < 0) still has a positive volume: the faces' orientation follows
//   the Jacobian's sign;
// - a ball (the 7 polynomial cells of construct's sphere) cut by a box through it, off its
//   knot lines: vol(S - B) + vol(S n B) = vol(S), vol(S) by the cells' own Gauss quadrature
//   (exact for polynomial cells), and vol(S n B) against the exact cap pi h^2 (3r - h) / 3
//   within the primitive's distance from the true sphere;
// - two boxes in a row, united: the faces between the three pieces are glued, and the faces
//   left are the union's outer boundary, of the polyhedron's area.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "trivox/error.hpp"
#include "trivox/construct/primitives.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/slice/model_boundary.hpp"
#include "trivox/slice/piece_measures.hpp"
#include "trivox/vmodel/boolean.hpp"
#include "boundary_fixtures.hpp"

using namespace trivox;
using vmodel::BooleanOp;
using vmodel::VModel;

using test::box;
using test::coons_cylinder;
using test::kPi;

namespace {

/// The area enclosed by the four arcs (Green's theorem; boundary_fixtures.hpp).
double arcs_area(double r) { return test::arcs_area_length(r).first; }

/// The sum of the pieces' volumes of a model (every cell a piece).
double total_volume(const VModel& m) {
  double v = 0;
  for (int c = 0; c < static_cast<int>(m.cells.size()); ++c) v += slice::piece_measures(m, c).volume;
  return v;
}

}  // namespace

TEST_CASE("measures of a box minus a box through it", "[piece_measures]") {
  // A = [0, 2]^2 x [0, 1]; B = [0.25, 0.75] x [0.5, 1.5] x [-1, 2]: A n B is the box
  // [0.25, 0.75] x [0.5, 1.5] x [0, 1] of volume 0.5 and centroid (0.5, 1, 0.5); A - B has
  // volume 3.5 and centroid ((4 x 1 - 0.5 x 0.5) / 3.5, 1, 0.5).
  const VModel A = box("A", {0, 0, 0}, {2, 2, 1}), B = box("B", {0.25, 0.5, -1}, {0.75, 1.5, 2});
  const VModel D = vmodel::boolean(A, B, BooleanOp::subtraction), I = vmodel::boolean(A, B, BooleanOp::intersection);
  REQUIRE(D.cells.size() == 1);
  REQUIRE(I.cells.size() == 1);
  const auto d = slice::piece_measures(D, 0), i = slice::piece_measures(I, 0);
  std::printf("box minus box: volume %.17g (expected 3.5), centroid (%.17g, %.17g, %.17g) (expected (%.17g, 1, 0.5)), area %.15g (18), closure %.2g, spread %.2g\n",
              d.volume, d.centroid[0], d.centroid[1], d.centroid[2], 3.75 / 3.5, d.area, d.closure, d.spread);
  std::printf("box and box: volume %.17g (expected 0.5), centroid (%.17g, %.17g, %.17g)\n", i.volume, i.centroid[0],
              i.centroid[1], i.centroid[2]);
  CHECK(!d.empty);
  CHECK(std::abs(d.volume - 3.5) <= 1e-12 * 3.5);
  CHECK(std::abs(i.volume - 0.5) <= 1e-12 * 0.5);
  CHECK(std::abs(d.volume + i.volume - 4) <= 1e-12 * 4);
  const std::array<double, 3> cd{3.75 / 3.5, 1, 0.5}, ci{0.5, 1, 0.5};
  for (std::size_t k = 0; k < 3; ++k) {
    CHECK(std::abs(d.centroid[k] - cd[k]) <= 1e-12);
    CHECK(std::abs(i.centroid[k] - ci[k]) <= 1e-12);
  }
  // Areas: A - B has top and bottom 4 - 0.5, sides 4 x 2, hole walls 2 x (0.5 + 1).
  CHECK(std::abs(d.area - 18) <= 1e-8 * 18);
  CHECK(std::abs(i.area - 2 * (0.5 + 0.5 + 1)) <= 1e-8 * 4);
  // Bounding boxes: A's for A - B, the small box for A n B.
  const std::array<std::array<double, 3>, 2> bd{{{0, 0, 0}, {2, 2, 1}}}, bi{{{0.25, 0.5, 0}, {0.75, 1.5, 1}}};
  for (std::size_t s = 0; s < 2; ++s)
    for (std::size_t k = 0; k < 3; ++k) {
      CHECK(std::abs(d.bbox[s][k] - bd[s][k]) <= 1e-12);
      CHECK(std::abs(i.bbox[s][k] - bi[s][k]) <= 1e-12);
    }
  CHECK(d.bbox_tight);
  CHECK(d.closure <= 1e-12);
}

TEST_CASE("measures of a box minus a cylinder through it", "[piece_measures]") {
  // A = [-1, 1]^2 x [0, 1] (volume 4); C: the Coons cylinder of radius 0.5, z in [-1, 2]
  // (volume 3 A_c). A n C is the cylinder of height 1 (A_c, centroid (0, 0, 0.5), box
  // [-0.5, 0.5]^2 x [0, 1]); A - C has 4 - A_c.
  const VModel A = box("A", {-1, -1, 0}, {1, 1, 1}), C = coons_cylinder(0.5, -1, 2);
  const double ac = arcs_area(0.5);
  REQUIRE(std::abs(ac - kPi * 0.25) < 1e-3);
  const VModel D = vmodel::boolean(A, C, BooleanOp::subtraction), I = vmodel::boolean(A, C, BooleanOp::intersection);
  const auto d = slice::piece_measures(D, 0), i = slice::piece_measures(I, 0);
  std::printf("box minus cylinder: volume %.17g (expected 4 - A_c = %.17g), centroid (%.3g, %.3g, %.17g), closure %.2g, spread %.2g\n",
              d.volume, 4 - ac, d.centroid[0], d.centroid[1], d.centroid[2], d.closure, d.spread);
  std::printf("box and cylinder: volume %.17g (expected A_c = %.17g), bbox (%.17g, %.17g) - (%.17g, %.17g)\n", i.volume, ac,
              i.bbox[0][0], i.bbox[0][1], i.bbox[1][0], i.bbox[1][1]);
  CHECK(std::abs(d.volume - (4 - ac)) <= 1e-8 * 4);
  CHECK(std::abs(i.volume - ac) <= 1e-8 * 4);
  // vol(A - C) + vol(A n C) = vol(A).
  CHECK(std::abs(d.volume + i.volume - 4) <= 1e-8 * 4);
  // The cross-section and the box are symmetric under quarter turns about the z axis.
  for (std::size_t k = 0; k < 2; ++k) {
    CHECK(std::abs(d.centroid[k]) <= 1e-9);
    CHECK(std::abs(i.centroid[k]) <= 1e-9);
  }
  CHECK(std::abs(d.centroid[2] - 0.5) <= 1e-9);
  CHECK(std::abs(i.centroid[2] - 0.5) <= 1e-9);
  for (std::size_t k = 0; k < 2; ++k) {
    CHECK(std::abs(i.bbox[0][k] + 0.5) <= 1e-8);
    CHECK(std::abs(i.bbox[1][k] - 0.5) <= 1e-8);
  }
  CHECK(std::abs(i.bbox[0][2]) <= 1e-12);
  CHECK(std::abs(i.bbox[1][2] - 1) <= 1e-12);

  // The union's pieces (A n C, A - C, C - A; C - A is two pieces of one cell): vol(A u C) +
  // vol(A n C) = vol(A) + vol(C).
  const VModel U = vmodel::boolean(A, C, BooleanOp::union_op);
  const double u = total_volume(U);
  std::printf("box union cylinder: %zu cells, volume %.17g; + A n C = %.17g (expected 4 + 3 A_c = %.17g)\n", U.cells.size(), u,
              u + i.volume, 4 + 3 * ac);
  CHECK(std::abs(u + i.volume - (4 + 3 * ac)) <= 1e-8 * (4 + 3 * ac));
}

TEST_CASE("measures of a box with a cylindrical cavity", "[piece_measures]") {
  // C (z in [0.25, 0.75]) lies inside A: no face of one meets a face of the other, so the
  // cavity's walls are C's six faces whole. vol(A - C) = 4 - 0.5 A_c.
  const VModel A = box("A", {-1, -1, 0}, {1, 1, 1}), C = coons_cylinder(0.5, 0.25, 0.75);
  const double ac = arcs_area(0.5);
  const VModel D = vmodel::boolean(A, C, BooleanOp::subtraction);
  REQUIRE(D.cells.size() == 1);
  const auto d = slice::piece_measures(D, 0);
  std::printf("box with a cavity: volume %.17g (expected %.17g), area %.15g, %d faces\n", d.volume, 4 - 0.5 * ac, d.area,
              d.faces);
  CHECK(d.faces == 12);
  CHECK(std::abs(d.volume - (4 - 0.5 * ac)) <= 1e-9 * 4);
  // The same volume from the plain cells' own quadrature-free truth: vol(A) - vol(C).
  CHECK(std::abs(d.volume - (slice::piece_measures(A, 0).volume - slice::piece_measures(C, 0).volume)) <= 1e-9 * 4);
}

TEST_CASE("measures of plain cells of either handedness", "[piece_measures]") {
  // A plain cell's boundary is its six faces: volume 2 x 3 x 4, centroid the middle, whether
  // its parametrisation is right- or left-handed.
  for (const bool mirror : {false, true}) {
    const VModel A = box("A", {1, 2, 3}, {3, 5, 7}, mirror);
    const auto m = slice::piece_measures(A, 0);
    CHECK(std::abs(m.volume - 24) <= 1e-12 * 24);
    CHECK(std::abs(m.area - 2 * (6 + 8 + 12)) <= 1e-12 * 52);
    CHECK(std::abs(m.centroid[0] - 2) <= 1e-12);
    CHECK(std::abs(m.centroid[1] - 3.5) <= 1e-12);
    CHECK(std::abs(m.centroid[2] - 5) <= 1e-12);
  }
  CHECK_THROWS_AS(slice::piece_measures(box("A", {0, 0, 0}, {1, 1, 1}), 1), Error);
}

TEST_CASE("an empty piece has no boundary", "[piece_measures]") {
  // A inside B: A - B is empty.
  const VModel A = box("A", {0, 0, 0}, {1, 1, 1}), B = box("B", {-1, -1, -1}, {2, 2, 2});
  const VModel D = vmodel::boolean(A, B, BooleanOp::subtraction);
  for (int c = 0; c < static_cast<int>(D.cells.size()); ++c) {
    const auto m = slice::piece_measures(D, c);
    CHECK(m.empty);
    CHECK(m.volume == 0);
  }
}

TEST_CASE("glued faces of two boxes united", "[piece_measures][model_boundary]") {
  // A = [0, 2] x [0, 1]^2 and B = [1, 3] x [-0.5, 1.5]^2 (no two faces coplanar). The union's
  // pieces: A n B = [1, 2] x [0, 1]^2, A - B = [0, 1] x [0, 1]^2, B - A = B less A n B. A n B
  // touches the two others on all six faces (area 6), so 12 units of face are glued (each
  // shared square seen from both sides); the outer boundary is B's 24 less the unit square where
  // A enters it, plus A's five faces outside B: 28. Volumes: 2 + 8 - 1 = 9.
  const VModel A = box("A", {0, 0, 0}, {2, 1, 1}), B = box("B", {1, -0.5, -0.5}, {3, 1.5, 1.5});
  const VModel U = vmodel::boolean(A, B, BooleanOp::union_op);
  const auto mb = slice::model_boundary(U);
  double all = 0;
  int glued = 0;
  for (const auto& f : mb.faces) {
    all += f.area;
    if (f.glued) {
      ++glued;
      CHECK(f.glued_to != f.cell);
      CHECK(f.glued_to >= 0);
    }
  }
  std::printf("two boxes united: %zu cells, %zu faces (%d glued), outer area %.15g (expected 28), glued %.15g (expected 12), all %.15g\n",
              U.cells.size(), mb.faces.size(), glued, mb.outer_area, mb.glued_area, all);
  CHECK(std::abs(mb.outer_area - 28) <= 1e-8 * 28);
  CHECK(std::abs(mb.glued_area - 12) <= 1e-8 * 12);
  CHECK(mb.partly_glued == 0);
  CHECK(std::abs(all - 40) <= 1e-8 * 40);
  CHECK(std::abs(total_volume(U) - 9) <= 1e-12 * 9);
  // Every face of the intersection piece is glued.
  for (const auto& f : mb.faces)
    if (U.cells[static_cast<std::size_t>(f.cell)].within.size() == 1) CHECK(f.glued);
}

TEST_CASE("coplanar faces are refused or measured right", "[piece_measures]") {
  // Massarwi & Elber 2016, Fig. 3: two boxes in a row sharing their y and z faces' planes.
  // boundary_faces classifies coplanar faces whole, so a shared plane may appear twice; the
  // self-checks then refuse the piece rather than report a wrong volume.
  const VModel A = box("O1", {0, 0, 0}, {2, 1, 1}), B = box("O2", {1, 0, 0}, {2, 1, 2});
  const VModel U = vmodel::boolean(A, B, BooleanOp::union_op);
  // A n B = [1, 2] x [0, 1]^2, A - B = [0, 1] x [0, 1]^2, B - A = [1, 2] x [0, 1] x [1, 2].
  for (int c = 0; c < static_cast<int>(U.cells.size()); ++c) {
    try {
      const auto m = slice::piece_measures(U, c);
      std::printf("Fig. 3 cell %s: volume %.17g\n", U.cells[static_cast<std::size_t>(c)].name.c_str(), m.volume);
      CHECK(std::abs(m.volume - 1) <= 1e-9);
    } catch (const Error& e) {
      std::printf("Fig. 3 cell %s: refused: %s\n", U.cells[static_cast<std::size_t>(c)].name.c_str(), e.what());
      SUCCEED("refused");
    }
  }
}



TEST_CASE("measures of a ball cut by a box", "[piece_measures]") {
  // S: radius 1 about the origin; B = [0.3, 2] x [-2, 2]^2. S n B is the cap of height 0.7.
  VModel S, B;
  for (auto& c : construct::build_primitive("S", construct::Sphere{{0, 0, 0}, 1})) S.cells.push_back({c.name, c.volume});
  for (auto& c : construct::build_primitive("B", construct::Box{{0.3, -2, -2}, {2, 2, 2}})) B.cells.push_back({c.name, c.volume});
  double vs = 0;
  for (const auto& c : S.cells) vs += geom::volume(c.volume);
  const VModel D = vmodel::boolean(S, B, BooleanOp::subtraction), I = vmodel::boolean(S, B, BooleanOp::intersection);
  const double d = total_volume(D), i = total_volume(I);
  const double h = 0.7, cap = kPi * h * h * (3 - h) / 3;
  std::printf("ball minus box: %.17g, ball and box: %.17g (cap %.17g), sum %.17g against the ball's cells %.17g\n", d, i, cap,
              d + i, vs);
  CHECK(std::abs(d + i - vs) <= 1e-8 * vs);
  CHECK(std::abs(i - cap) <= 1e-3 * cap);
}

TEST_CASE("glued faces of plain cells", "[model_boundary]") {
  // Two plain cells face to face, [0, 1]^3 and [1, 2] x [0, 1]^2: their x = 1 faces are glued
  // to each other (area 1 each), the outer boundary is that of [0, 2] x [0, 1]^2, 10. A small
  // box [0.25, 0.75]^2 x [1, 1.5] standing on the first: its bottom is glued whole, the first
  // cell's top only partly (its patch's middle is under the small box: glued_to set, not glued).
  VModel m = box("L", {0, 0, 0}, {1, 1, 1});
  m.cells.push_back(box("R", {1, 0, 0}, {2, 1, 1}).cells[0]);
  auto mb = slice::model_boundary(m);
  REQUIRE(mb.faces.size() == 12);
  CHECK(mb.faces[1].glued);  // L's u1
  CHECK(mb.faces[1].glued_to == 1);
  CHECK(mb.faces[6].glued);  // R's u0
  CHECK(mb.faces[6].glued_to == 0);
  CHECK(std::abs(mb.outer_area - 10) <= 1e-12 * 10);
  CHECK(std::abs(mb.glued_area - 2) <= 1e-12 * 2);
  CHECK(mb.partly_glued == 0);
  m.cells.push_back(box("S", {0.25, 0.25, 1}, {0.75, 0.75, 1.5}).cells[0]);
  mb = slice::model_boundary(m);
  REQUIRE(mb.faces.size() == 18);
  CHECK(mb.faces[16].glued);  // S's w0
  CHECK(mb.faces[16].glued_to == 0);
  CHECK(!mb.faces[5].glued);  // L's w1: the small box covers a quarter of it
  CHECK(mb.faces[5].glued_to == 2);
  CHECK(mb.partly_glued == 1);
  CHECK_THROWS_AS(slice::model_boundary(VModel{}), Error);
}

TEST_CASE("measures refuse more conditions than allowed", "[piece_measures]") {
  const VModel A = box("A", {0, 0, 0}, {2, 2, 1}), B = box("B", {0.25, 0.5, -1}, {0.75, 1.5, 2});
  const VModel D = vmodel::boolean(A, B, BooleanOp::subtraction);
  slice::PieceMeasureOptions o;
  o.max_conditions = 0;
  CHECK_THROWS_AS(slice::piece_measures(D, 0, o), Error);
  o.max_conditions = 1;
  CHECK(std::abs(slice::piece_measures(D, 0, o).volume - 3.5) <= 1e-12 * 3.5);
}

TEST_CASE("measures of a box minus a multi-cell cylinder", "[piece_measures]") {
  // C: construct's 5-cell cylinder (r 0.5 about the z axis, z in [-1, 2]); its cells are
  // prisms, so the part in A = [-1, 1]^2 x [0, 1] is a third of its volume (the cells' own
  // quadrature). vol(A - C) + vol(A n C) = vol(A) = 4.
  const VModel A = box("A", {-1, -1, 0}, {1, 1, 1});
  VModel C;
  C.properties = {"r"};
  for (auto& c : construct::build_primitive("C", construct::Cylinder{{0, 0, -1}, {0, 0, 1}, 0.5, 3})) {
    // xyz only: append the property coordinate A carries.
    std::vector<double> pts;
    const auto src = c.volume.points();
    for (std::size_t i = 0; i < src.size(); i += 3) pts.insert(pts.end(), {src[i], src[i + 1], src[i + 2], 0.5});
    C.cells.push_back({c.name, spline::Trivariate(c.volume.knot_vectors(), 4, pts)});
  }
  double vc = 0;
  for (const auto& c : C.cells) vc += geom::volume(c.volume);
  const VModel D = vmodel::boolean(A, C, BooleanOp::subtraction), I = vmodel::boolean(A, C, BooleanOp::intersection);
  const double d = total_volume(D), i = total_volume(I);
  std::printf("box minus 5-cell cylinder: %.17g, intersection %.17g (vol(C) / 3 = %.17g), sum %.17g (4)\n", d, i, vc / 3, d + i);
  CHECK(std::abs(d + i - 4) <= 1e-8 * 4);
  CHECK(std::abs(i - vc / 3) <= 1e-8 * vc);
}
