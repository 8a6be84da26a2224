// Booleans of V-models (vmodel/boolean.hpp) as the locator sees them. Truths: membership of
// analytic solids (boxes, and a ring from an exact-radius revolution tolerance) at random
// points, for union, intersection, subtraction and nested expressions; the cell a point falls
// in (A - B, A n B, B - A) from the same analytic predicates; blended properties are the sum
// (clipped) or mean of the inputs' values.
#include <catch2/catch.hpp>

#include <cmath>
#include <functional>
#include <random>

#include "trivox/construct/constructors.hpp"
#include "trivox/error.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/slice/locator.hpp"
#include "trivox/slice/trim.hpp"
#include "trivox/vmodel/topology.hpp"
#include "trivox/vmodel/boolean.hpp"

using namespace trivox;
using spline::KnotVector;
using vmodel::BooleanOp;
using vmodel::VModel;

namespace {

/// An axis-aligned box cell with one constant property.
VModel box(const std::string& name, std::array<double, 3> lo, std::array<double, 3> hi, double value) {
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) pts.insert(pts.end(), {i ? hi[0] : lo[0], j ? hi[1] : lo[1], k ? hi[2] : lo[2], value});
  const KnotVector b = KnotVector::bezier(2);
  VModel m;
  m.properties = {"r"};
  m.cells.push_back({name, spline::Trivariate({b, b, b}, 4, pts)});
  return m;
}

/// The ring 1 <= r <= 2, 0 <= z <= 1 about z, property 0.1: a rectangle revolved within
/// `tolerance` (relative) of the exact circle.
VModel ring_model(double tolerance) {
  std::vector<double> rect;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) rect.insert(rect.end(), {1.0 + i, 0.0, double(j), 0.1});
  const spline::Surface profile({KnotVector::bezier(2), KnotVector::bezier(2)}, 4, rect);
  construct::Revolution rev;
  rev.relative_tolerance = tolerance;
  VModel ring;
  ring.properties = {"r"};
  ring.cells.push_back({"ring", construct::revolve(profile, rev)});
  return ring;
}

bool in_box(const slice::Vec3& p, std::array<double, 3> lo, std::array<double, 3> hi) {
  for (std::size_t d = 0; d < 3; ++d)
    if (p[d] < lo[d] || p[d] > hi[d]) return false;
  return true;
}

double box_margin(const slice::Vec3& p, std::array<double, 3> lo, std::array<double, 3> hi) {
  double m = 1e300;
  for (std::size_t d = 0; d < 3; ++d) m = std::min({m, std::abs(p[d] - lo[d]), std::abs(p[d] - hi[d])});
  return m;
}

/// Random points in [lo, hi] away from the given surfaces (margin() > 1e-4), checked against
/// `inside` and, for points inside, the expected cell name.
void check_membership(const VModel& m, std::array<double, 3> lo, std::array<double, 3> hi,
                      const std::function<bool(const slice::Vec3&)>& inside,
                      const std::function<double(const slice::Vec3&)>& margin,
                      const std::function<std::string(const slice::Vec3&)>& cell_name = {}) {
  const slice::Locator loc(m, {.tolerance = 1e-9});
  std::mt19937 rng(5);
  int tested = 0, in = 0;
  for (int n = 0; n < 4000; ++n) {
    slice::Vec3 p;
    for (std::size_t d = 0; d < 3; ++d) p[d] = std::uniform_real_distribution<double>(lo[d], hi[d])(rng);
    if (margin(p) < 1e-4) continue;
    ++tested;
    const auto r = loc.locate(p);
    INFO("p = (" << p[0] << ", " << p[1] << ", " << p[2] << ")");
    REQUIRE(r.inside == inside(p));
    if (r.inside) {
      ++in;
      if (cell_name) CHECK(m.cells[static_cast<std::size_t>(r.cell)].name == cell_name(p));
    }
  }
  CHECK(tested > 3000);
  CHECK(in > 200);
  CHECK(tested - in > 200);
}

}  // namespace

TEST_CASE("union intersection and subtraction of two boxes: exact membership and cells", "[boolean]") {
  // Massarwi & Elber 2016, Fig. 3: O1 = [0,2]x[0,1]x[0,1], O2 = [1,2]x[0,1]x[0,2]: A = O1 - O2, B =
  // O1 n O2, C = O2 - O1.
  const std::array<double, 3> a0{0, 0, 0}, a1{2, 1, 1}, b0{1, 0, 0}, b1{2, 1, 2};
  const VModel A = box("A", a0, a1, 0.25), B = box("B", b0, b1, 0.5);
  const auto margin = [&](const slice::Vec3& p) { return std::min(box_margin(p, a0, a1), box_margin(p, b0, b1)); };
  const auto inA = [&](const slice::Vec3& p) { return in_box(p, a0, a1); };
  const auto inB = [&](const slice::Vec3& p) { return in_box(p, b0, b1); };
  const std::array<double, 3> lo{-0.5, -0.5, -0.5}, hi{2.5, 1.5, 2.5};

  const VModel U = vmodel::boolean(A, B, BooleanOp::union_op);
  REQUIRE(U.cells.size() == 3);
  CHECK(U.cells[0].name == "A&B");
  CHECK(U.cells[1].name == "A");
  CHECK(U.cells[2].name == "B");
  check_membership(U, lo, hi, [&](auto& p) { return inA(p) || inB(p); }, margin,
                   [&](auto& p) { return inA(p) && inB(p) ? "A&B" : inA(p) ? "A" : "B"; });
  check_membership(vmodel::boolean(A, B, BooleanOp::intersection), lo, hi,
                   [&](auto& p) { return inA(p) && inB(p); }, margin);
  check_membership(vmodel::boolean(A, B, BooleanOp::subtraction), lo, hi,
                   [&](auto& p) { return inA(p) && !inB(p); }, margin);
  check_membership(vmodel::boolean(B, A, BooleanOp::subtraction), lo, hi,
                   [&](auto& p) { return inB(p) && !inA(p); }, margin);

  // Properties: sum clipped, mean, first.
  const slice::Locator loc(U, {.tolerance = 1e-9});
  const slice::Vec3 p{1.5, 0.5, 0.5};
  const auto r = loc.locate(p);
  REQUIRE(r.inside);
  double x[3], v[1];
  loc.eval(r.cell, r.uvw, x, v);
  CHECK(v[0] == Approx(0.25));
  CHECK(loc.admits(r.cell, p, v));
  CHECK(v[0] == Approx(0.75));
  for (auto [rule, expect] : {std::pair{vmodel::BlendRule::mean, 0.375}, std::pair{vmodel::BlendRule::first, 0.25}}) {
    const VModel I = vmodel::boolean(A, B, BooleanOp::intersection, {.blend = rule});
    const slice::Locator li(I, {.tolerance = 1e-9});
    const auto ri = li.locate(p);
    REQUIRE(ri.inside);
    li.eval(ri.cell, ri.uvw, x, v);
    CHECK(li.admits(ri.cell, p, v));
    CHECK(v[0] == Approx(expect));
  }
  // Sum clipped to 1.
  const VModel H = vmodel::boolean(box("A", a0, a1, 0.75), box("B", b0, b1, 0.5), BooleanOp::intersection);
  const slice::Locator lh(H, {.tolerance = 1e-9});
  const auto rh = lh.locate(p);
  lh.eval(rh.cell, rh.uvw, x, v);
  CHECK(lh.admits(rh.cell, p, v));
  CHECK(v[0] == 1.0);
}

TEST_CASE("nested Booleans with a curved cell keep exact membership", "[boolean]") {
  // A ring 1 <= r <= 2, 0 <= z <= 1 (revolution within 1e-6 of the exact circle, below the 1e-4 margin), a box
  // cutting it, and a second box subtracted from the result, then that result subtracted from
  // a third box: C - ((ring u box1) - box2).
  const VModel ring = ring_model(1e-6);
  const std::array<double, 3> b10{-0.5, -0.5, -0.5}, b11{0.5, 2.5, 1.5};
  const std::array<double, 3> b20{1.2, -3, 0.5}, b21{3, 3, 2};
  const std::array<double, 3> c0{-2.5, -0.25, 0.25}, c1{2.5, 0.25, 0.75};
  const auto in_ring = [](const slice::Vec3& p) {
    const double r = std::hypot(p[0], p[1]);
    return r >= 1 && r <= 2 && p[2] >= 0 && p[2] <= 1;
  };
  const auto ring_margin = [](const slice::Vec3& p) {
    const double r = std::hypot(p[0], p[1]);
    return std::min({std::abs(r - 1), std::abs(r - 2), std::abs(p[2]), std::abs(p[2] - 1)});
  };
  const VModel X = vmodel::boolean(vmodel::boolean(ring, box("b1", b10, b11, 0.2), BooleanOp::union_op),
                                   box("b2", b20, b21, 0.3), BooleanOp::subtraction);
  const auto inX = [&](const slice::Vec3& p) { return (in_ring(p) || in_box(p, b10, b11)) && !in_box(p, b20, b21); };
  const auto margin = [&](const slice::Vec3& p) {
    return std::min({ring_margin(p), box_margin(p, b10, b11), box_margin(p, b20, b21), box_margin(p, c0, c1)});
  };
  check_membership(X, {-2.5, -2.5, -0.5}, {2.5, 2.5, 1.5}, inX, margin);
  const VModel Y = vmodel::boolean(box("c", c0, c1, 0.4), X, BooleanOp::subtraction);
  check_membership(Y, {-2.5, -0.5, 0.0}, {2.5, 0.5, 1.0}, [&](auto& p) { return in_box(p, c0, c1) && !inX(p); },
                   margin);
}

TEST_CASE("Booleans refuse models that cannot be combined", "[boolean]") {
  VModel a = box("A", {0, 0, 0}, {1, 1, 1}, 0.1), b = box("B", {0, 0, 0}, {1, 1, 1}, 0.1);
  b.properties = {"g"};
  try {
    vmodel::boolean(a, b, BooleanOp::union_op);
    FAIL("expected an error");
  } catch (const Error& e) {
    CHECK_THAT(std::string(e.what()), Catch::Contains("properties [r] and [g]; expected the same property names"));
  }
  VModel empty;
  empty.properties = {"r"};
  CHECK_THROWS_AS(vmodel::boolean(a, empty, BooleanOp::subtraction), Error);
  // Names stay unique when the inputs share them.
  const VModel u = vmodel::boolean(a, box("A", {0.5, 0, 0}, {2, 1, 1}, 0.2), BooleanOp::union_op);
  REQUIRE(u.cells.size() == 3);
  CHECK(u.cells[0].name == "A&A");
  CHECK(u.cells[1].name == "A");
  CHECK(u.cells[2].name == "A.2");
}

TEST_CASE("the distance blend of Massarwi & Elber 2016, Eq. 2 weights each input by its boundary distance", "[boolean]") {
  const std::array<double, 3> a0{0, 0, 0}, a1{2, 1, 1}, b0{1, 0, 0}, b1{3, 1, 1};
  for (double k : {1.0, 2.0}) {
    const VModel I = vmodel::boolean(box("A", a0, a1, 0.0), box("B", b0, b1, 1.0), BooleanOp::intersection,
                                     {.blend = vmodel::BlendRule::distance, .power = k});
    REQUIRE(I.cells.size() == 1);
    REQUIRE(I.cells[0].boundaries.size() == 2);
    CHECK(I.cells[0].boundaries[0].size() == 6);
    const slice::Locator loc(I, {.tolerance = 1e-9});
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    for (int n = 0; n < 300; ++n) {
      const slice::Vec3 p{1 + U(rng), U(rng), U(rng)};
      const double dA = std::min({p[0], 2 - p[0], p[1], 1 - p[1], p[2], 1 - p[2]});
      const double dB = std::min({p[0] - 1, 3 - p[0], p[1], 1 - p[1], p[2], 1 - p[2]});
      const double expect = std::pow(dB, k) / (std::pow(dA, k) + std::pow(dB, k));
      const auto r = loc.locate(p);
      REQUIRE(r.inside);
      double x[3], v[1];
      loc.eval(r.cell, r.uvw, x, v);
      CHECK(loc.admits(r.cell, p, v));
      CHECK(v[0] == Approx(expect).margin(1e-9));
    }
    // On A's boundary inside B only B's value remains (C0 with B - A), and vice versa.
    for (auto [p, expect] : {std::pair{slice::Vec3{2.0, 0.5, 0.5}, 1.0}, std::pair{slice::Vec3{1.0, 0.5, 0.5}, 0.0}}) {
      const auto r = loc.locate(p);
      REQUIRE(r.inside);
      double x[3], v[1];
      loc.eval(r.cell, r.uvw, x, v);
      CHECK(loc.admits(r.cell, p, v));
      CHECK(v[0] == Approx(expect).margin(1e-9));
    }
  }
}

TEST_CASE("Massarwi & Elber 2016, Fig. 3: two boxes united give three box cells with the stated topology", "[boolean]") {
  // O1 = [0,2]x[0,1]x[0,1], O2 = [1,2]x[0,1]x[0,2]: cells A = O1 - O2, B = O1 n O2, C = O2 - O1.
  // Paper: 3 V-cells, 2 internal and 14 boundary V-surfaces (16), 18 half-V-surfaces,
  // 28 V-curves, 16 V-points.
  const std::array<double, 3> a0{0, 0, 0}, a1{2, 1, 1}, b0{1, 0, 0}, b1{2, 1, 2};
  const VModel U = vmodel::boolean(box("O1", a0, a1, 0.25), box("O2", b0, b1, 0.5), BooleanOp::union_op);
  // The trimmed cells' volumes before untrimming: each piece is a unit cube.
  {
    const slice::Locator loc(U, {.tolerance = 1e-9});
    for (int c = 0; c < 3; ++c) CHECK(slice::trimmed_volume(loc, c) == Approx(1.0).epsilon(1e-12));
  }
  // Trimming curves: O2's face x = 1 cuts O1's front face (v0, parameters (u, w)) along u = 1/2;
  // O1's top z = 1 cuts O2's face u0 (parameters (v, w)) along w = 1/2.
  const auto has_line = [](const vmodel::VCell& c, spline::Face f, int coord, double value) {
    for (const auto& t : c.trim_curves) {
      if (t.face != f) continue;
      for (const auto& k : t.curves) {
        bool on = true;
        for (int i = 0; i <= 20; ++i) on = on && std::abs(k.eval({k.domain(0)[0] + i * (k.domain(0)[1] - k.domain(0)[0]) / 20})[coord] - value) < 1e-9;
        if (on) return true;
      }
    }
    return false;
  };
  CHECK(has_line(U.cells[0], spline::Face::v0, 0, 0.5));
  CHECK(has_line(U.cells[1], spline::Face::v0, 0, 0.5));
  CHECK(has_line(U.cells[2], spline::Face::u0, 1, 0.5));
  const VModel T = slice::untrim(U);
  REQUIRE(T.cells.size() == 3);
  const auto n = vmodel::counts(vmodel::build_topology(T));
  CHECK(n.v_cells == 3);
  CHECK(n.v_surfaces == 16);
  CHECK(n.half_v_surfaces == 18);
  CHECK(n.v_curves == 28);
  CHECK(n.v_points == 16);
  for (const auto& c : T.cells) CHECK(geom::volume(c.volume) == Approx(1.0).epsilon(1e-9));
  // Membership is unchanged.
  const auto inA = [&](const slice::Vec3& p) { return in_box(p, a0, a1); };
  const auto inB = [&](const slice::Vec3& p) { return in_box(p, b0, b1); };
  check_membership(T, {-0.5, -0.5, -0.5}, {2.5, 1.5, 2.5}, [&](auto& p) { return inA(p) || inB(p); },
                   [&](const slice::Vec3& p) { return std::min(box_margin(p, a0, a1), box_margin(p, b0, b1)); },
                   [&](auto& p) { return inA(p) && inB(p) ? "O1&O2" : inA(p) ? "O1" : "O2"; });
}

TEST_CASE("the volume of a curved trimmed cell is close to the analytic one", "[boolean]") {
  // The ring 1 <= r <= 2, 0 <= z <= 1 minus the half-space slab x >= 1.2, 0.5 <= z: removed
  // (segment of the r = 2 disk beyond x = 1.2) x 0.5 = (4 acos(0.6) - 1.2 * 1.6) * 0.5.
  const VModel ring = ring_model(1e-8);
  const VModel X = vmodel::boolean(ring, box("b2", {1.2, -3, 0.5}, {3, 3, 2}, 0.3), BooleanOp::subtraction);
  const slice::Locator loc(X, {.tolerance = 1e-9});
  const double exact = 3 * M_PI - (4 * std::acos(0.6) - 1.2 * 1.6) * 0.5;
  CHECK(slice::trimmed_volume(loc, 0) == Approx(exact).epsilon(5e-3));
  // Not a parameter box: untrim leaves it alone.
  CHECK(slice::untrim(X) == X);
}
