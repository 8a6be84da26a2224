// Masalha et al. 2021, Sec. 6 / 6.1 (fillet/corners.hpp): a column standing through a plate. C is
// the column's square footprint, four straight pieces C_{w1,j} meeting at four convex corners where
// the column's vertical edges (perpendicular to the plate) cross the plate. Expected values from
// the geometry: the column's rails meet on its edges at r = o + d2 z, the plate's rails end at
// distance d1 from o; each piece's fillet is the Hermite section swept along a straight line of
// length 2, and each bridge is that section revolved a quarter turn about the edge (the plate is
// a plane and the edge its normal), so its volume is Pappus' (pi/2) int X dA = (pi/2) oint X^2/2 dZ.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>

#include "corner.hpp"
#include "trivox/error.hpp"
#include "trivox/fillet/corners.hpp"

using fillet_test::box_cell;
using fillet_test::hermite_area;
using trivox::Error;
namespace fillet = trivox::fillet;
namespace spline = trivox::spline;

namespace {

/// int over the region between the legs and the Hermite section of X dA (X the distance from
/// the Z axis, the edge): by Green's theorem oint X^2 / 2 dZ, only the section contributes;
/// exact with 8 Gauss points (degree 8 integrand).
double hermite_moment(double d1, double d2, double tau) {
  return fillet_test::hermite_integral(d1, d2, tau, [](double X, double, double, double dZ) { return 0.5 * X * X * dZ; });
}

/// Fillet options with the rails' distances d1, d2 on the two sides and the blend's tau.
fillet::FilletOptions options(double d1, double d2, double tau) {
  fillet::FilletOptions o;
  o.distance = {d1, d2};
  o.blend.tau = tau;
  return o;
}

double dist(const std::array<double, 3>& a, const std::vector<double>& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

struct Column {
  spline::Trivariate plate = box_cell({-4, -4, -2}, {4, 4, 0}, 1.0);
  spline::Trivariate column = box_cell({-1, -1, -1}, {1, 1, 3}, 2.0);
  std::vector<fillet::SideFace> side1{{&plate, spline::Face::w1, "plate/w1"}};
  std::vector<fillet::SideFace> side2{{&column, spline::Face::u0, "column/u0"},
                                      {&column, spline::Face::v1, "column/v1"},
                                      {&column, spline::Face::u1, "column/u1"},
                                      {&column, spline::Face::v0, "column/v0"}};
};

}  // namespace

TEST_CASE("fillet across a column's faces: Sec. 6 pieces and Sec. 6.1 bridges at the convex corners", "[fillet][corners]") {
  Column c;
  const double d1 = 1.0, d2 = 0.5, tau = 1.0;
  const fillet::FilletOptions o = options(d1, d2, tau);
  const auto m = fillet::fillet_across(c.side1, c.side2, o);
  REQUIRE(m.pieces.size() == 4);
  CHECK(m.closed);
  REQUIRE(m.junctions.size() == 4);
  REQUIRE(m.corners.size() == 4);
  const double area = hermite_area(d1, d2, tau);
  const double bridge_volume = std::numbers::pi / 2 * hermite_moment(d1, d2, tau);
  double pieces_volume = 0.0, total = 0.0;
  for (const auto& p : m.pieces) {
    REQUIRE(p.fillets.size() == 1);
    double v = 0.0;
    for (double x : p.fillets[0].quality.cell_volume) v += x;
    CHECK(v == Approx(2.0 * area).epsilon(1e-9));  // the section along a segment of length 2
    pieces_volume += v;
  }
  for (const auto& j : m.junctions) {
    CHECK(j.kind == fillet::JunctionKind::corner);
    CHECK(j.gap_side == 0);  // the plate is smooth at o; the column has the edge
    CHECK(j.angle == Approx(std::numbers::pi / 2).epsilon(1e-9));
    CHECK(std::abs(std::abs(j.o[0]) - 1) < 1e-9);
    CHECK(std::abs(std::abs(j.o[1]) - 1) < 1e-9);
    CHECK(std::abs(j.o[2]) < 1e-9);
    CHECK(std::hypot(j.r[0] - j.o[0], j.r[1] - j.o[1], j.r[2] - j.o[2] - d2) < 1e-9);
    CHECK(std::hypot(j.p[0] - j.o[0], j.p[1] - j.o[1], j.p[2] - j.o[2]) == Approx(d1).epsilon(1e-9));
    CHECK(std::hypot(j.q[0] - j.o[0], j.q[1] - j.o[1], j.q[2] - j.o[2]) == Approx(d1).epsilon(1e-9));
  }
  const double tol = 1e-7 * std::sqrt(8 * 8 + 8 * 8 + 5 * 5);  // fillet_faces' default
  for (const auto& cf : m.corners) {
    const auto& q = cf.quality;
    const auto& j = m.junctions[cf.junction];
    INFO("corner at " << j.o[0] << ", " << j.o[1]);
    CHECK(q.jacobian() == "positive");
    CHECK(q.det_min > 0.0);
    CHECK(q.end_error < 1e-9);  // the rail interpolates p and q
    CHECK(q.o_error < 1e-9);    // the fan collapses onto o
    CHECK(q.r_error < 1e-9);    // the section ends at r
    CHECK(q.radius_error < tol);
    CHECK(q.g1_angle < 1e-5);
    // C0 with both neighbours: pinned to their end sections, so one function (rounding level);
    // before pinning the bridge's own section ended within the fit tolerance of theirs.
    CHECK(q.glue[0] < 1e-12);
    CHECK(q.glue[1] < 1e-12);
    CHECK(q.glue_before[0] < 10 * tol);
    CHECK(q.glue_before[1] < 10 * tol);
    CHECK(q.property_jump[0] < 1e-12);  // g_1 = 1 and g_2 = 2 on both sides of the glue
    CHECK(q.property_jump[1] < 1e-12);
    CHECK(cf.ends[0] != cf.ends[1]);
    const double v = q.cell_volume[0] + q.cell_volume[1];
    CHECK(v == Approx(bridge_volume).epsilon(1e-5));
    total += v;
    // The fan's corners: p and q at the rail (v = 0, w = 0) ends, o at v = 1; properties g_1 = 1
    // on the plate's sub-region and g_2 = 2 on the column's.
    const auto& h0 = cf.cells[0];
    const auto du = h0.domain(0);
    const auto a = h0.eval({du[0], 0.0, 0.0}), b = h0.eval({du[1], 0.0, 0.0});
    CHECK(std::min(dist(j.p, a), dist(j.q, a)) < 1e-9);
    CHECK(std::min(dist(j.p, b), dist(j.q, b)) < 1e-9);
    CHECK(dist(j.p, a) + dist(j.p, b) > d1);  // one of each
    CHECK(dist(j.o, h0.eval({0.5 * (du[0] + du[1]), 1.0, 0.0})) < 1e-9);
    CHECK(h0.eval({0.3, 0.4, 0.0})[3] == Approx(1.0).epsilon(1e-12));
    CHECK(cf.cells[1].eval({0.3, 0.4, 0.0})[3] == Approx(2.0).epsilon(1e-12));
    // The column's side is the edge segment o r: singular by construction.
    CHECK(dist(j.r, cf.cells[1].eval({0.7, 1.0, 0.0})) < 1e-9);
  }
  // The whole fillet ring: four sweeps and four quarter revolutions.
  CHECK(pieces_volume + total == Approx(4 * 2.0 * area + 4 * bridge_volume).epsilon(1e-5));
}

TEST_CASE("fillet across faces: gaps left open without bridges (Fig. 12 (c))", "[fillet][corners]") {
  Column c;
  fillet::FilletOptions o;
  o.distance = {1.0, 0.5};
  fillet::CornerOptions co;
  co.bridge = false;
  const auto m = fillet::fillet_across(c.side1, c.side2, o, co);
  CHECK(m.pieces.size() == 4);
  CHECK(m.junctions.size() == 4);
  CHECK(m.corners.empty());
}

namespace {

/// An L-shaped footprint's concave corner at (1, 1): boxes A = [1,2] x [0,1] and B = [0,1] x
/// [1,2] (the L's arms) standing on the plate; their faces y = 1 (A's v1, x in [1, 2]) and x = 1
/// (B's u1, y in [1, 2]) meet at the reflex edge x = y = 1, perpendicular to the plate.
struct Notch {
  spline::Trivariate plate = box_cell({-4, -4, -2}, {4, 4, 0}, 1.0);
  spline::Trivariate a = box_cell({1, 0, -1}, {2, 1, 3}, 2.0);
  spline::Trivariate b = box_cell({0, 1, -1}, {1, 2, 3}, 2.0);
  std::vector<fillet::SideFace> side1{{&plate, spline::Face::w1, "plate/w1"}};
  std::vector<fillet::SideFace> side2{{&a, spline::Face::v1, "a/v1"}, {&b, spline::Face::u1, "b/u1"}};
};

}  // namespace

TEST_CASE("fillet across faces: a concave corner, rails clipped and stitched (Sec. 6, Fig. 12 (b))", "[fillet][corners]") {
  Notch c;
  const double d1 = 0.5, d2 = 0.25, tau = 1.0;
  const fillet::FilletOptions o = options(d1, d2, tau);
  const auto m = fillet::fillet_across(c.side1, c.side2, o);
  REQUIRE(m.pieces.size() == 2);
  CHECK_FALSE(m.closed);
  REQUIRE(m.junctions.size() == 1);
  CHECK(m.corners.empty());
  const auto& j = m.junctions[0];
  CHECK(j.kind == fillet::JunctionKind::stitch);
  CHECK(j.gap_side == 0);
  // The plate's rails y = 1 + d1 (A) and x = 1 + d1 (B) cross at (1 + d1, 1 + d1, 0); the arms'
  // rails meet on the edge at r = (1, 1, d2).
  CHECK(std::hypot(j.x[0] - (1 + d1), j.x[1] - (1 + d1), j.x[2]) < 1e-9);
  CHECK(std::hypot(j.o[0] - 1, j.o[1] - 1, j.o[2]) < 1e-9);
  CHECK(std::hypot(j.r[0] - 1, j.r[1] - 1, j.r[2] - d2) < 1e-9);
  // The crossing's parameters: d1 along each unit-length rail from the corner's end.
  for (std::size_t k = 0; k < 2; ++k) {
    const double t = j.crossing[k], e = j.end[k];
    CHECK(std::abs(t - e) > 0.0);
    CHECK(std::abs(t - e) < 1.0);
  }
  const double tol = 1e-7 * std::sqrt(8 * 8 + 8 * 8 + 5 * 5);
  CHECK(j.glue_before < 10 * tol);  // both clipped ends lie in the plane x = y, the mirror of each other
  CHECK(j.glue < 1e-12);            // stitched: the second's end pinned onto the first's
  // Each piece is the Hermite section R swept along its unit-length arm, cut by the plane x = y:
  // int_R (1 - X) dA, X the distance from the edge.
  const double want = hermite_area(d1, d2, tau) - hermite_moment(d1, d2, tau);
  for (const auto& p : m.pieces) {
    REQUIRE(p.fillets.size() == 1);
    const auto& q = p.fillets[0].quality;
    CHECK(q.jacobian() == "positive");
    CHECK(q.det_min > 0.0);
    CHECK(q.cell_volume[0] + q.cell_volume[1] == Approx(want).epsilon(1e-6));
    CHECK(q.glue < 10 * tol);
    // The clipped end in the stitch plane x = y, the kept part on the arm's side.
    for (const auto& h : p.fillets[0].cells) {
      const auto du = h.domain(0);
      double in_plane = std::numeric_limits<double>::infinity(), off = 0.0;
      for (const double u : {du[0], du[1]}) {
        double worst = 0.0;
        for (int a = 0; a <= 8; ++a)
          for (int b = 0; b <= 8; ++b) {
            const auto x = h.eval({u, a / 8.0, b / 8.0});
            worst = std::max(worst, std::abs(x[0] - x[1]));
          }
        in_plane = std::min(in_plane, worst);
        off = std::max(off, worst);
      }
      CHECK(in_plane < 10 * tol);
      CHECK(off > 0.5);  // the far end stays at x = 2 (or y = 2)
    }
  }
}

TEST_CASE("fillet across faces: the plate's rails flipped into the column's footprint cross at four concave corners",
          "[fillet][corners]") {
  Column c;
  fillet::FilletOptions o;
  o.distance = {0.5, 0.5};
  o.flip = {true, false};
  const auto m = fillet::fillet_across(c.side1, c.side2, o);
  REQUIRE(m.junctions.size() == 4);
  CHECK(m.corners.empty());
  for (const auto& j : m.junctions) {
    CHECK(j.kind == fillet::JunctionKind::stitch);
    // The rails x = +-0.5 and y = +-0.5 inside the square cross at (+-0.5, +-0.5, 0).
    CHECK(std::hypot(std::abs(j.x[0]) - 0.5, std::abs(j.x[1]) - 0.5, j.x[2]) < 1e-9);
    CHECK(j.glue < 1e-12);
  }
}

TEST_CASE("fillet across faces: bad input names the place", "[fillet][corners]") {
  Column c;
  fillet::FilletOptions o;
  o.distance = {1.0, 0.5};
  SECTION("a concave corner whose rails cross beyond the pieces") {
    Notch n;
    o.distance = {1.5, 0.25};  // the plate's rails would cross at (2.5, 2.5), past the unit arms
    try {
      (void)fillet::fillet_across(n.side1, n.side2, o);
      FAIL("no error");
    } catch (const Error& e) {
      CHECK(e.kind() == trivox::ErrorKind::bad_input);
      CHECK_THAT(e.what(), Catch::Contains("concave corner") && Catch::Contains("plate/w1 x ") &&
                               Catch::Contains("do not cross within both pieces") && Catch::Contains("fillet corner at ("));
    }
  }
  SECTION("faces that do not meet") {
    const std::vector<fillet::SideFace> top{{&c.column, spline::Face::w1, "column/w1"}};
    try {
      (void)fillet::fillet_across(c.side1, top, o);
      FAIL("no error");
    } catch (const Error& e) {
      CHECK(e.kind() == trivox::ErrorKind::bad_input);
      CHECK_THAT(e.what(), Catch::Contains("plate/w1 and column/w1 do not intersect"));
    }
  }
  SECTION("the flend section has no bridge") {
    o.blend.section = fillet::Section::flend;
    CHECK_THROWS_WITH(fillet::fillet_across(c.side1, c.side2, o), Catch::Contains("Hermite section"));
  }
}

namespace {

/// The column turned 45 degrees about z (its vertical edges at (+-sqrt 2, 0) and (0, +-sqrt 2)),
/// through a plate made of two cells joined along the seam x = 0 (planar, so G1): the corners
/// (0, +-sqrt 2) lie on the seam, and their gaps, from p = o + d1 (+-1, 1) / sqrt 2 (or the
/// mirror) to q, span both plate cells; the corners (+-sqrt 2, 0) lie inside one.
struct SeamColumn {
  static spline::Trivariate turned(spline::Trivariate h) {
    const double c = std::sqrt(0.5);
    for (int i = 0; i < h.count(0) * h.count(1) * h.count(2); ++i) {
      double* x = h.point(i).data();
      const double a = x[0], b = x[1];
      x[0] = c * (a - b);
      x[1] = c * (a + b);
    }
    return h;
  }
  spline::Trivariate west = box_cell({-4, -4, -2}, {0, 4, 0}, 1.0);
  spline::Trivariate east = box_cell({0, -4, -2}, {4, 4, 0}, 1.0);
  spline::Trivariate column = turned(box_cell({-1, -1, -1}, {1, 1, 3}, 2.0));
  std::vector<fillet::SideFace> side1{{&west, spline::Face::w1, "west/w1"}, {&east, spline::Face::w1, "east/w1"}};
  std::vector<fillet::SideFace> side2{{&column, spline::Face::u0, "column/u0"},
                                      {&column, spline::Face::v1, "column/v1"},
                                      {&column, spline::Face::u1, "column/u1"},
                                      {&column, spline::Face::v0, "column/v0"}};
};

}  // namespace

TEST_CASE("fillet across faces: a convex corner on a seam of the smooth body, B_d across two faces (Fig. 12 (d))",
          "[fillet][corners]") {
  SeamColumn c;
  const double d1 = 1.0, d2 = 0.5, tau = 1.0;
  const fillet::FilletOptions o = options(d1, d2, tau);
  const auto m = fillet::fillet_across(c.side1, c.side2, o);
  REQUIRE(m.pieces.size() == 4);
  CHECK(m.closed);
  REQUIRE(m.junctions.size() == 4);
  // Two corners inside one plate cell (one bridge each), two on the seam (two parts each).
  REQUIRE(m.corners.size() == 6);
  const double area = hermite_area(d1, d2, tau);
  const double quarter = std::numbers::pi / 2 * hermite_moment(d1, d2, tau);  // Pappus, a quarter turn
  const double tol = 1e-7 * std::sqrt(8 * 8 + 8 * 8 + 5 * 5);
  for (const auto& p : m.pieces) {
    REQUIRE(p.fillets.size() == 1);
    double v = 0.0;
    for (double x : p.fillets[0].quality.cell_volume) v += x;
    CHECK(v == Approx(2.0 * area).epsilon(1e-9));  // the section along a face of length 2
  }
  std::vector<double> per_junction(m.junctions.size(), 0.0);
  int split = 0;
  for (const auto& cf : m.corners) {
    const auto& q = cf.quality;
    const auto& j = m.junctions[cf.junction];
    INFO("corner at " << j.o[0] << ", " << j.o[1] << ", part " << cf.part);
    CHECK(j.kind == fillet::JunctionKind::corner);
    CHECK(j.gap_side == 0);
    CHECK(q.jacobian() == "positive");
    CHECK(q.det_min > 0.0);
    CHECK(q.end_error < 1e-9);
    CHECK(q.o_error < 1e-9);
    CHECK(q.r_error < 1e-9);
    CHECK(q.radius_error < tol);
    CHECK(q.g1_angle < 1e-5);
    CHECK(q.glue[0] < 1e-12);  // to the neighbour or, split, to the other part
    CHECK(q.glue[1] < 1e-12);
    CHECK(q.glue_before[0] < 10 * tol);
    CHECK(q.glue_before[1] < 10 * tol);
    CHECK(q.property_jump[0] < 1e-12);
    CHECK(q.property_jump[1] < 1e-12);
    CHECK(cf.ends[0] != cf.ends[1]);
    const double v = q.cell_volume[0] + q.cell_volume[1];
    per_junction[cf.junction] += v;
    const bool on_seam = std::abs(j.o[0]) < 1e-9;
    CHECK(on_seam == (cf.part >= 0));
    if (cf.part < 0) {
      CHECK(v == Approx(quarter).epsilon(1e-5));
      continue;
    }
    ++split;
    // Each part an eighth turn about the edge (the seam bisects the right angle between p and q).
    CHECK(v == Approx(quarter / 2).epsilon(1e-5));
    // The seam point s = o + d1 (0, +-1, 0), the same on both plate cells; the faces are G1 there.
    const double sy = j.o[1] + std::copysign(d1, j.o[1]);
    for (const auto& s : q.seam_point) CHECK(std::hypot(s[0], s[1] - sy, s[2]) < 1e-9);
    CHECK(q.seam_gap < 1e-9);
    CHECK(q.seam_angle < 1e-12);
    CHECK(q.seam_glue < 1e-12);
    CHECK(q.seam_glue_before < 10 * tol);
    CHECK(q.seam_property_jump < 1e-12);
    // Part 0 on the arriving piece's plate cell, part 1 on the leaving one's: the rail's end at
    // s on the seam, and g_1 = 1 on the plate's sub-region, g_2 = 2 on the column's.
    const auto& h = cf.cells[0];
    const auto du = h.domain(0);
    const double us = du[cf.ends[cf.part == 0 ? 1 : 0] == spline::Face::u0 ? 0 : 1];
    const auto s = h.eval({us, 0.0, 0.0});
    CHECK(std::hypot(s[0], s[1] - sy, s[2]) < 1e-9);
    CHECK(h.eval({0.3, 0.4, 0.0})[3] == Approx(1.0).epsilon(1e-12));
    CHECK(cf.cells[1].eval({0.3, 0.4, 0.0})[3] == Approx(2.0).epsilon(1e-12));
  }
  CHECK(split == 4);
  // Every corner, split or not, is the quarter turn of the unturned column's test.
  for (double v : per_junction) CHECK(v == Approx(quarter).epsilon(1e-5));
}

TEST_CASE("fillet across faces: a gap over two faces that do not join at a seam names the place", "[fillet][corners]") {
  SeamColumn c;
  // The east plate cell ends at y = 2.2: it still holds its pieces' rails (p at y = sqrt 2 +
  // 1 / sqrt 2 < 2.2), but not the seam point s = (0, sqrt 2 + 1, 0) of the corner (0, sqrt 2).
  c.east = box_cell({0, -4, -2}, {4, 2.2, 0}, 1.0);
  fillet::FilletOptions o;
  o.distance = {1.0, 0.5};
  try {
    (void)fillet::fillet_across(c.side1, c.side2, o);
    FAIL("no error");
  } catch (const Error& e) {
    CHECK(e.kind() == trivox::ErrorKind::bad_input);
    CHECK_THAT(e.what(), Catch::Contains("fillet corner at (") && Catch::Contains("1.41421") && Catch::Contains("west/w1") &&
                             Catch::Contains("east/w1") && Catch::Contains("seam through"));
  }
}
