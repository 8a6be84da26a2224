// Point location against geometry known in closed form: axis-aligned boxes, a rational quarter
// annulus (exact circles: inside iff r1 <= |(x,y)| <= r2, x, y >= 0, 0 <= z <= h), and a curved
// tricubic block, where the located (u,v,w) must map back onto the point.
#include <catch2/catch.hpp>

#include <filesystem>
#include <random>

#include "locator_fixtures.hpp"
#include "trivox/error.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/slice/locator.hpp"
#include "trivox/spline/refine.hpp"

using namespace trivox;
using namespace trivox::test;
using slice::Locator;
using slice::Vec3;

namespace {
double dist(const double* x, const Vec3& p) {
  return std::sqrt((x[0] - p[0]) * (x[0] - p[0]) + (x[1] - p[1]) * (x[1] - p[1]) + (x[2] - p[2]) * (x[2] - p[2]));
}
}  // namespace

TEST_CASE("locate: a box cell, inside and outside") {
  const auto m = model_of({box_cell({1, 2, 3}, {4, 6, 8}, {0.25})}, {"a"});
  const Locator loc(m);
  const auto r = loc.locate({2.5, 3, 7});
  REQUIRE(r.inside);
  CHECK(r.converged);
  CHECK(r.cell == 0);
  // Trilinear box: u = (x - 1) / 3, v = (y - 2) / 4, w = (z - 3) / 5.
  CHECK(r.uvw[0] == Approx(0.5).margin(1e-6));
  CHECK(r.uvw[1] == Approx(0.25).margin(1e-6));
  CHECK(r.uvw[2] == Approx(0.8).margin(1e-6));
  for (const Vec3 p : {Vec3{0.9, 3, 4}, Vec3{4.001, 3, 4}, Vec3{2, 1.99, 4}, Vec3{2, 3, 8.01}, Vec3{100, 100, 100}}) {
    const auto o = loc.locate(p);
    CHECK_FALSE(o.inside);
    CHECK(o.cell == -1);
    CHECK(o.converged);
  }
  // On a face (within the tolerance) counts as inside.
  CHECK(loc.locate({4.0, 3, 4}).inside);
  // Not a point at all: outside, flagged.
  const auto nan = loc.locate({std::nan(""), 3, 4});
  CHECK_FALSE(nan.inside);
  CHECK_FALSE(nan.converged);
}

TEST_CASE("locate: rational quarter annulus agrees with the analytic inside test") {
  const double r1 = 5, r2 = 10, h = 4;
  const auto m = model_of({quarter_annulus(r1, r2, h)}, {"v"});
  slice::LocatorOptions opt;
  opt.tolerance = 1e-6;
  const Locator loc(m, opt);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> X(-1, 11), Z(-1, 5);
  int inside = 0, checked = 0;
  for (int n = 0; n < 4000; ++n) {
    const Vec3 p{X(rng), X(rng), Z(rng)};
    const double rho = std::hypot(p[0], p[1]);
    // Distance to the boundary, to skip points within the tolerance of it.
    const double margin = std::min({std::abs(rho - r1), std::abs(rho - r2), std::abs(p[0]), std::abs(p[1]), std::abs(p[2]), std::abs(p[2] - h)});
    if (margin < 1e-5) continue;
    const bool truth = rho > r1 && rho < r2 && p[0] > 0 && p[1] > 0 && p[2] > 0 && p[2] < h;
    const auto r = loc.locate(p);
    INFO("p = " << p[0] << ", " << p[1] << ", " << p[2]);
    CHECK(r.converged);
    REQUIRE(r.inside == truth);
    ++checked;
    if (!truth) continue;
    ++inside;
    double x[3], v;
    loc.eval(0, r.uvw, x, &v);
    CHECK(dist(x, p) < opt.tolerance);
    // The radial parameter is linear in the radius; the property equals it.
    CHECK(r.uvw[1] == Approx((rho - r1) / (r2 - r1)).margin(1e-6));
    CHECK(v == Approx(r.uvw[1]).margin(1e-12));
    CHECK(r.uvw[2] == Approx(p[2] / h).margin(1e-6));
  }
  CHECK(checked > 3900);
  CHECK(inside > 500);
}

TEST_CASE("locate: curved tricubic cell maps the located (u,v,w) back onto the point") {
  const auto m = model_of({curved_tricubic()}, {"r", "g", "b"});
  const auto& cell = m.cells[0].volume;
  slice::LocatorOptions opt;
  opt.tolerance = 1e-5;
  const Locator loc(m, opt);
  // Points of the cell at known parameters: locate must find them, with equal properties.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(0.001, 0.999);
  slice::LocateResult prev;
  for (int n = 0; n < 2000; ++n) {
    const Vec3 t{U(rng), U(rng), U(rng)};
    const auto x = cell.eval(t);
    const Vec3 p{x[0], x[1], x[2]};
    const auto r = n % 2 ? loc.locate(p, &prev) : loc.locate(p);  // with and without a hint
    REQUIRE(r.inside);
    CHECK(r.converged);
    const auto y = cell.eval(r.uvw);
    CHECK(dist(y.data(), p) < opt.tolerance);
    // The map is injective (positive Jacobian), so the parameters are the ones we started from.
    for (int d = 0; d < 3; ++d) CHECK(r.uvw[static_cast<std::size_t>(d)] == Approx(t[static_cast<std::size_t>(d)]).margin(1e-4));
    double props[3], xyz[3];
    loc.eval(0, r.uvw, xyz, props);
    for (int h = 0; h < 3; ++h) CHECK(std::abs(props[h] - y[static_cast<std::size_t>(3 + h)]) < 1e-12);
    prev = r;
  }
  // Outside: beyond the corners, which the corner control points pin down exactly.
  CHECK_FALSE(loc.locate({-0.01, -0.01, -0.01}).inside);
  CHECK_FALSE(loc.locate({10.01, 10.01, 10.01}).inside);
  CHECK_FALSE(loc.locate({50, 5, 5}).inside);
}

TEST_CASE("locate: overlapping cells, the first in file order wins") {
  const auto a = box_cell({0, 0, 0}, {2, 2, 2}, {1});
  const auto b = box_cell({1, 1, 1}, {3, 3, 3}, {2});
  const Locator ab(model_of({a, b}, {"p"}));
  CHECK(ab.locate({1.5, 1.5, 1.5}).cell == 0);
  CHECK(ab.locate({2.5, 2.5, 2.5}).cell == 1);
  CHECK(ab.locate({0.5, 0.5, 0.5}).cell == 0);
  const Locator ba(model_of({b, a}, {"p"}));
  CHECK(ba.locate({1.5, 1.5, 1.5}).cell == 0);
  CHECK(ba.locate({0.5, 0.5, 0.5}).cell == 1);
  // A hint into the later cell does not override the earlier one.
  const auto hint = ab.locate({2.5, 2.5, 2.5});
  CHECK(ab.locate({1.5, 1.5, 1.5}, &hint).cell == 0);
}

TEST_CASE("locate: the Fichera corner's seven cubes") {
  const auto m = io::load_model(std::filesystem::path(TRIVOX_SOURCE_DIR) / "models" / "gismo" / "fichera.xml");
  const Locator loc(m);
  // The corner is [-1,1]^3 without one octant; every cube's centre is found in that cube.
  for (std::size_t c = 0; c < m.cells.size(); ++c) {
    const auto x = m.cells[c].volume.eval({0.5, 0.5, 0.5});
    const auto r = loc.locate({x[0], x[1], x[2]});
    CHECK(r.inside);
    CHECK(r.cell == static_cast<int>(c));
  }
  int missing = 0;
  for (int o = 0; o < 8; ++o) {
    const Vec3 p{o & 1 ? 0.5 : -0.5, o & 2 ? 0.5 : -0.5, o & 4 ? 0.5 : -0.5};
    missing += !loc.locate(p).inside;
  }
  CHECK(missing == 1);
}

TEST_CASE("locate: bad options and cells are reported") {
  const auto m = model_of({box_cell({0, 0, 0}, {1, 1, 1})});
  slice::LocatorOptions opt;
  opt.tolerance = 0;
  CHECK_THROWS_AS(Locator(m, opt), Error);
  auto bad = m;
  bad.properties = {"r"};  // the cell has 3 coordinates, the model says 4
  CHECK_THROWS_WITH(Locator(bad), Catch::Contains("cell0") && Catch::Contains("expected 4"));
  CHECK_THROWS_AS(slice::model_bounds(vmodel::VModel{}), Error);
  const auto b = slice::model_bounds(model_of({box_cell({1, 2, 3}, {4, 5, 6}), box_cell({-1, 0, 0}, {0, 7, 1})}));
  CHECK(b[0] == Vec3{-1, 0, 0});
  CHECK(b[1] == Vec3{4, 7, 6});
}

TEST_CASE("locate: expansions equal the spline's first partials, and step bounds bound the second and third") {
  // Two pieces per direction (an interior knot), so bounds are per piece and in global parameters.
  auto cell = curved_tricubic();
  for (int d = 0; d < 3; ++d) cell = spline::refine_uniform(cell, d, 1);
  const auto m = model_of({cell}, {"r", "g", "b"});
  const slice::Locator loc(m);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(0, 1);
  const auto slots = spline::derivative_multi_indices<3>(2);
  for (int n = 0; n < 500; ++n) {
    const Vec3 t{U(rng), U(rng), U(rng)};
    slice::Expansion e;
    REQUIRE(loc.expand(0, t, e));
    const auto d = cell.eval_derivatives(t, 2);  // 10 slots x 6 coordinates
    for (int h = 0; h < 3; ++h) {
      CHECK(e.x[static_cast<std::size_t>(h)] == Approx(d[static_cast<std::size_t>(h)]).margin(1e-12));
      for (int k = 0; k < 3; ++k)
        CHECK(e.jac[static_cast<std::size_t>(k)][static_cast<std::size_t>(h)] == Approx(d[static_cast<std::size_t>(6 * (1 + k) + h)]).margin(1e-9));
    }
    for (int h = 0; h < 3; ++h) {
      CHECK(e.props[static_cast<std::size_t>(h)] == Approx(d[static_cast<std::size_t>(3 + h)]).margin(1e-12));
      for (int k = 0; k < 3; ++k)
        CHECK(e.grad[static_cast<std::size_t>(h)][static_cast<std::size_t>(k)] == Approx(d[static_cast<std::size_t>(6 * (1 + k) + 3 + h)]).margin(1e-9));
    }
    const auto& b = loc.step_bounds(e.piece);
    REQUIRE(b.valid);
    for (int dd = 0; dd < 3; ++dd) CHECK((t[static_cast<std::size_t>(dd)] >= b.lo[static_cast<std::size_t>(dd)] && t[static_cast<std::size_t>(dd)] <= b.hi[static_cast<std::size_t>(dd)]));
    for (std::size_t s = 4; s < 10; ++s) {  // the second partials
      const auto& a = slots[s];
      int i = -1, j = -1;
      for (int k = 0; k < 3; ++k)
        for (int c = 0; c < a[static_cast<std::size_t>(k)]; ++c) (i < 0 ? i : j) = k;
      const double* v = &d[6 * s];
      CHECK(std::hypot(v[0], v[1], v[2]) <= b.b2[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] * (1 + 1e-9));
      for (int h = 3; h < 6; ++h) CHECK(std::abs(v[h]) <= b.p2[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] * (1 + 1e-9));
    }
    // The third partials of the properties, by central differences of the second (h = 1e-5,
    // away from the pieces' joins at 0.5, where they jump): d/dt_k of d^2 P / dt_i dt_j.
    bool near_join = false;
    for (std::size_t k = 0; k < 3; ++k) near_join = near_join || std::abs(t[k] - 0.5) < 1e-3;
    if (!near_join) {
      const double h = 1e-5;
      for (std::size_t k = 0; k < 3; ++k) {
        Vec3 tp = t, tm = t;
        tp[k] += h;
        tm[k] -= h;
        const auto dp = cell.eval_derivatives(tp, 2), dm = cell.eval_derivatives(tm, 2);
        for (std::size_t s = 4; s < 10; ++s) {
          const auto& a = slots[s];
          std::array<std::size_t, 3> ix{0, 0, k};
          std::size_t n2 = 0;
          for (std::size_t q = 0; q < 3; ++q)
            for (int c = 0; c < a[q]; ++c) ix[n2++] = q;
          for (std::size_t c = 3; c < 6; ++c) {
            const double third = (dp[6 * s + c] - dm[6 * s + c]) / (2 * h);
            const double bound = b.p3[ix[0]][ix[1]][ix[2]];
            CHECK(std::abs(third) <= bound * (1 + 1e-5) + 1e-6);
            CHECK(bound == b.p3[ix[2]][ix[0]][ix[1]]);  // symmetric
            CHECK(bound == b.p3[ix[1]][ix[2]][ix[0]]);
          }
        }
      }
    }
  }
  // Tight where the property is one monomial: a unit cube whose property is u^3 v, with Bezier
  // coefficients [i = 3] j / 3 (u^3 = B_3,3(u), v = sum_j (j/3) B_j,3(v)): d^3/du^3 = 6 v and
  // d^3/du^2 dv = 6 u reach 6, d^3/dv^3, d^3/du dv^2 and d^3/dw^3 are 0.
  {
    std::vector<double> pts;  // u fastest; x = u, y = v, z = w (linear precision)
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) pts.insert(pts.end(), {i / 3.0, j / 3.0, k / 3.0, i == 3 ? j / 3.0 : 0.0});
    const auto cubic = KnotVector::bezier(4);
    const auto mono = model_of({Trivariate({cubic, cubic, cubic}, 4, pts)}, {"r"});
    const slice::Locator lm(mono);
    slice::Expansion e;
    REQUIRE(lm.expand(0, {0.5, 0.5, 0.5}, e));
    const auto& b = lm.step_bounds(e.piece);
    CHECK(b.p3[0][0][0] == Approx(6.0).epsilon(1e-9));
    CHECK(b.p3[0][0][1] == Approx(6.0).epsilon(1e-9));
    CHECK(b.p3[1][1][1] == Approx(0.0).margin(1e-12));  // up to rounding in the differences
    CHECK(b.p3[0][1][1] == Approx(0.0).margin(1e-12));
    CHECK(b.p3[2][2][2] == Approx(0.0).margin(1e-12));
  }
  // Rational pieces have no expansion (their cells take the exact path).
  const auto q = model_of({quarter_annulus(5, 10, 4)}, {"v"});
  const slice::Locator lq(q);
  slice::Expansion e;
  CHECK_FALSE(lq.expand(0, {0.5, 0.5, 0.5}, e));
}

TEST_CASE("locate: a piece's properties at many points equal the spline's, also past the piece's box") {
  // Orders (4, 4, 4) with two pieces per direction (a kernel with the orders at compile time)
  // and (5, 4, 6) (the run-time orders); 1, 7, 8, 9 and 20 points (whole and partial groups of
  // eight lanes; chunks of up to four points take a four-lane kernel with AVX2), and each point
  // alone gives the same floats as in a chunk of eight (the same operations lane by lane).
  auto a = curved_tricubic();
  for (int d = 0; d < 3; ++d) a = spline::refine_uniform(a, d, 1);
  auto b = spline::elevate(spline::elevate(curved_tricubic(), 0, 1), 2, 2);
  for (const auto& cell : {a, b}) {
    const auto m = model_of({cell}, {"r", "g", "b"});
    const slice::Locator loc(m);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> U(0, 1);
    for (int n : {1, 3, 4, 5, 7, 8, 9, 12, 20}) {
      slice::Expansion e;
      REQUIRE(loc.expand(0, {U(rng), U(rng), U(rng)}, e));
      const auto& bd = loc.step_bounds(e.piece);
      std::vector<Vec3> t(static_cast<std::size_t>(n));
      for (auto& p : t)
        for (std::size_t d = 0; d < 3; ++d) p[d] = bd.lo[d] + U(rng) * (bd.hi[d] - bd.lo[d]);
      std::vector<double> v(static_cast<std::size_t>(n) * 3);
      loc.piece_properties(e.piece, t.data(), n, v.data());
      for (int j = 0; j < n; ++j) {
        const auto x = cell.eval(t[static_cast<std::size_t>(j)]);
        for (int h = 0; h < 3; ++h) CHECK(v[static_cast<std::size_t>(j * 3 + h)] == Approx(x[static_cast<std::size_t>(3 + h)]).margin(1e-12));
        double alone[3];
        loc.piece_properties(e.piece, &t[static_cast<std::size_t>(j)], 1, alone);
        for (int h = 0; h < 3; ++h) CHECK(alone[h] == v[static_cast<std::size_t>(j * 3 + h)]);
      }
    }
  }
  // Past its box a piece's polynomial continues (not clamped): `a` is one polynomial refined
  // into pieces, so one piece's polynomial gives the spline's values over the whole domain.
  const auto m = model_of({a}, {"r", "g", "b"});
  const slice::Locator loc(m);
  slice::Expansion e;
  REQUIRE(loc.expand(0, {0.1, 0.1, 0.1}, e));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(0, 1);
  std::vector<Vec3> t(40);
  for (auto& p : t) p = {U(rng), U(rng), U(rng)};
  std::vector<double> v(t.size() * 3);
  loc.piece_properties(e.piece, t.data(), static_cast<int>(t.size()), v.data());
  for (std::size_t j = 0; j < t.size(); ++j) {
    const auto x = a.eval(t[j]);
    for (std::size_t h = 0; h < 3; ++h) CHECK(v[j * 3 + h] == Approx(x[3 + h]).margin(1e-10));
  }
}

TEST_CASE("locate: points next to a degenerate rail are placed, not failed") {
  // A fillet-like cusp, as the fillets' cells are next to their rails: cubic along the rail (u),
  // quadratic across (v), linear through (w), with the face v = 1 collapsed onto the rail, where
  // dX/dw = 0 and Newton's Jacobian is singular; the faces w = 0 and w = 1 are tangent there.
  // X(u, v, w) = (4u, b(u) + s, w s^2) with s = 1 - v and b the cubic bump with Bezier
  // ordinates 0, 0.4, 0.4, 0: the section x = 4u is {0 <= y - b(u) <= 1, 0 <= z <= (y - b)^2},
  // an exact inside test. Near the rail, Newton clamped at v = 1 stalls; the subdivision
  // fallback must still decide.
  const spline::KnotVector cub = spline::KnotVector::bezier(4), quad = spline::KnotVector::bezier(3),
                           lin = spline::KnotVector::bezier(2);
  std::vector<double> pts;
  // w s^2 in Bernstein form of degree 2 in v (s = 1 - v): ordinates w, 0, 0; s: 1, 1/2, 0.
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 4; ++i) {
        const double bump = (i == 1 || i == 2) ? 0.4 : 0.0;
        pts.insert(pts.end(), {4.0 * i / 3.0, bump + 1.0 - j / 2.0, j == 0 ? 1.0 * k : 0.0});
      }
  const auto m = model_of({Trivariate({cub, quad, lin}, 3, pts)}, {});
  slice::LocatorOptions opt;
  opt.tolerance = 1e-6;
  const Locator loc(m, opt);
  const auto& cell = m.cells[0].volume;
  auto b = [](double u) { return 1.2 * u * (1.0 - u); };  // 3 (0.4) u (1-u)^2 + 3 (0.4) u^2 (1-u)
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(0.05, 0.95), dy(-0.05, 0.05), dz(-2e-3, 3e-3);
  int inside = 0, outside = 0;
  for (int n = 0; n < 4000; ++n) {
    const double u = U(rng), yr = dy(rng), z = dz(rng);
    const Vec3 p{4.0 * u, b(u) + yr, z};
    // Exact: inside iff 0 <= yr <= 1 and 0 <= z <= yr^2; skip points within 1e-4 of its boundary.
    const double margin = std::min({yr, z, yr * yr - z});
    if (std::abs(margin) < 1e-4 && !(yr < -1e-4 || z < -1e-4)) continue;
    const bool want = yr >= 0 && z >= 0 && z <= yr * yr;
    const auto res = loc.locate(p);
    INFO("point " << p[0] << " " << p[1] << " " << p[2] << " (y - b " << yr << ")");
    CHECK(res.converged);
    CHECK(res.inside == want);
    (want ? inside : outside)++;
    if (res.inside) {
      const auto y = cell.eval(res.uvw);
      CHECK(dist(y.data(), p) < opt.tolerance);
    }
  }
  CHECK(inside > 200);
  CHECK(outside > 200);
}

TEST_CASE("locate: a point just off the filleted teapot's rail is placed outside") {
  // A piece of the built teapot's handle_fillet.1b (u in [0.77, 0.776], 11 KB; cut from
  // `trivox build models/teapot.json` with spline::restrict_to(volume, 0, 0.77, 0.776) and
  // io::save_model, the model's properties kept): its face v = 1 is
  // the rail, a curve. The voxel centre below lies 0.0093 mm from the rail, outside the cell;
  // with the sampler's options at J750 pitches, one level of subdivision left it undecided (the
  // slice's one inversion failure).
  const auto m = io::load_model(std::filesystem::path(TRIVOX_SOURCE_DIR) / "tests/data/teapot_rail.json");
  REQUIRE(m.cells.size() == 1);
  const auto& cell = m.cells[0].volume;
  const Vec3 p{-17.1095, 2.225, 21.58125};
  // The independent answer: the distance to the cell's points on a lattice of its parameters,
  // the whole domain coarsely and the strip v in [0.95, 1] next to the rail finely (steps of
  // 1e-4 in u and 2.5e-5 in v, which move the point by about 1.3e-3 and 2.5e-5 mm there, with
  // |X_u| about 13 mm and |X_v| about 1 mm per unit, and X_w vanishing at the rail): 0.0093 mm,
  // 340 times the tolerance, so the centre is outside.
  double nearest = 1e9;
  const auto du = cell.domain(0);
  for (int fine = 0; fine < 2; ++fine)
    for (int a = 0; a <= 60; ++a)
      for (int b = 0; b <= 2000; b += fine ? 1 : 20)
        for (int c = 0; c <= 20; ++c) {
          const double v = fine ? 0.95 + 0.05 * b / 2000.0 : b / 2000.0;
          const std::array<double, 3> t{du[0] + (du[1] - du[0]) * a / 60.0, v, c / 20.0};
          nearest = std::min(nearest, dist(cell.eval(t).data(), p));
        }
  CHECK(nearest == Approx(0.00932).margin(1e-4));
  slice::LocatorOptions opt;  // the sampler's at J750 (sampler.cpp, options_for)
  opt.tolerance = 1e-3 * 0.027;
  opt.leaf_deviation = 25.4 / 300.0;
  opt.fine_leaf_deviation = 0.25 * opt.leaf_deviation;
  const Locator loc(m, opt);
  const auto r = loc.locate(p);
  CHECK(r.converged);
  CHECK_FALSE(r.inside);
}
