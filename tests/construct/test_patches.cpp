// Patch merging, offsets and tube solids (construct/patches.hpp, construct/tube_solid.hpp).
// Truths:
//  - merging: patch (i, j) of the grid is the merged surface on [i, i+1] x [j, j+1], so
//    merged(i + s, j + t) = patch_ij(s, t) at every sample (both evaluated independently);
//  - offsets: where |d| is below the radius of curvature, S + d n is at distance |d| from S, so
//    the distance of the fitted offset from S (geom::SurfaceDistance, an independent Newton
//    solver) is |d| within the stated tolerance; a cylinder of radius r offset by d is the
//    cylinder of radius r + d (its S_u x S_v points outward);
//  - tube solids: a cylinder's tube gives five cells with det J > 0 (check_validity) whose
//    volumes add up to pi r^2 h (geom::volume, Gauss quadrature of det J), within the
//    polynomial circle's own accuracy.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "trivox/construct/constructors.hpp"
#include "trivox/construct/patches.hpp"
#include "trivox/construct/tube_solid.hpp"
#include "trivox/error.hpp"
#include "trivox/geom/closest_point.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/geom/validity.hpp"
#include "trivox/spline/refine.hpp"

using namespace trivox;
using spline::KnotVector;
using spline::Surface;

namespace {

/// A bicubic Bezier patch on [0, 1]^2 with control points p(i, j) (i along u).
template <class F>
Surface bezier(F p) {
  std::vector<double> pts;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      const auto x = p(i, j);
      pts.insert(pts.end(), x.begin(), x.end());
    }
  return Surface({KnotVector::bezier(4), KnotVector::bezier(4)}, 3, pts);
}

/// A 3 x 2 grid of bicubic patches cut from one C2 spline surface (a wavy height field on
/// [0, 3] x [0, 2], one knot span per patch), each reparametrised onto [0, 1]^2: they meet C2,
/// so the surface's normal (and its offset) is continuous across them. (Patches that meet only
/// C0 have a crease, across which an offset jumps.)
std::vector<Surface> wavy_grid() {
  const auto z = [](double x, double y) { return std::sin(1.3 * x) * std::cos(0.7 * y) + 0.1 * x * y; };
  const KnotVector ku = KnotVector::uniform(4, 3, 0.0, 3.0), kv = KnotVector::uniform(4, 2, 0.0, 2.0);
  std::vector<double> pts;
  for (double y : kv.greville())
    for (double x : ku.greville()) pts.insert(pts.end(), {x, y, z(x, y)});
  const Surface whole({ku, kv}, 3, pts);
  std::vector<Surface> out;
  for (int pj = 0; pj < 2; ++pj)
    for (int pi = 0; pi < 3; ++pi)
      out.push_back(construct::normalized(spline::restrict_to(spline::restrict_to(whole, 0, pi, pi + 1.0), 1, pj, pj + 1.0)));
  return out;
}

/// The cylinder x^2 + y^2 = r^2, z in [0, h], u around (counterclockwise from +x), v up.
Surface cylinder(double r, double h) {
  spline::Curve line({KnotVector::bezier(2)}, 3, std::vector<double>{r, 0, 0, r, 0, h});
  construct::Revolution rev;
  rev.relative_tolerance = 1e-9;
  return spline::swap_directions(construct::revolve(line, rev), 0, 1);  // revolve: v around
}

}  // namespace

TEST_CASE("merged patches equal every patch on its square", "[construct][patches]") {
  const auto grid = wavy_grid();
  construct::MergeReport rep;
  const Surface m = construct::merge_patches(grid, 3, 1e-12, &rep);
  for (const auto& p : grid) REQUIRE(p.counts() == std::array<int, 2>{4, 4});
  CHECK(rep.max_gap <= 1e-14);
  CHECK(m.domain(0) == std::array<double, 2>{0.0, 3.0});
  CHECK(m.domain(1) == std::array<double, 2>{0.0, 2.0});
  // 3 cubic pieces along u: 3 * 3 + 1 control points; 2 along v: 7. Joints of multiplicity 3.
  CHECK(m.counts() == std::array<int, 2>{10, 7});
  CHECK(m.knots(0).multiplicity(1.0) == 3);
  CHECK(m.knots(1).multiplicity(1.0) == 3);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double worst = 0.0;
  for (int n = 0; n < 400; ++n) {
    const int i = n % 3, j = (n / 3) % 2;
    const double s = unit(rng), t = unit(rng);
    const auto a = m.eval({i + s, j + t}), b = grid[static_cast<std::size_t>(i + 3 * j)].eval({s, t});
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(a[static_cast<std::size_t>(c)] - b[static_cast<std::size_t>(c)]));
  }
  CHECK(worst <= 1e-14);
}

TEST_CASE("merging refuses patches that do not meet, or of other spaces", "[construct][patches]") {
  auto grid = wavy_grid();
  // Swapping two patches of a row breaks the shared edge.
  std::swap(grid[0], grid[1]);
  try {
    (void)construct::merge_patches(grid, 3, 1e-9);
    FAIL("no error");
  } catch (const Error& e) {
    CHECK_THAT(e.what(), Catch::Contains("does not meet its neighbour"));
  }
  auto g2 = wavy_grid();
  g2[4] = spline::elevate(g2[4], 0);
  CHECK_THROWS_AS(construct::merge_patches(g2, 3, 1e-9), Error);
  CHECK_THROWS_AS(construct::merge_patches(wavy_grid(), 4, 1e-9), Error);  // 6 patches in rows of 4
}

TEST_CASE("an offset is |d| from the surface within its tolerance", "[construct][patches]") {
  const Surface s = construct::merge_patches(wavy_grid(), 3, 1e-12);
  for (double d : {0.15, -0.15}) {
    construct::OffsetOptions o;
    o.tolerance = 1e-4;
    construct::OffsetReport rep;
    const Surface off = construct::offset_surface(s, d, o, &rep);
    INFO("d " << d << ": error " << rep.max_error << " after " << rep.refinements << " refinements");
    CHECK(rep.max_error <= o.tolerance);
    const geom::SurfaceDistance dist(s, 8);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.3, 2.7), v(0.3, 1.7);  // away from the boundary, where
    double worst = 0.0;                                                // the closest point is interior
    for (int n = 0; n < 300; ++n) {
      const auto x = off.eval({u(rng), v(rng)});
      const auto cp = dist.closest({x[0], x[1], x[2]});
      worst = std::max(worst, std::abs(cp.distance - std::abs(d)));
    }
    CHECK(worst <= o.tolerance);
  }
}

TEST_CASE("a cylinder offset by d is the cylinder of radius r + d", "[construct][patches]") {
  const double r = 2.0, h = 3.0;
  const Surface c = cylinder(r, h);
  for (double d : {0.5, -0.5}) {
    construct::OffsetOptions o;
    o.tolerance = 1e-6;
    const Surface off = construct::offset_surface(c, d, o);
    double worst = 0.0;
    for (int a = 0; a <= 40; ++a)
      for (int b = 0; b <= 10; ++b) {
        const auto x = off.eval({c.domain(0)[0] + a / 40.0 * (c.domain(0)[1] - c.domain(0)[0]),
                                 c.domain(1)[0] + b / 10.0 * (c.domain(1)[1] - c.domain(1)[0])});
        worst = std::max(worst, std::abs(std::hypot(x[0], x[1]) - (r + d)));
      }
    // The revolved cylinder is within 1e-9 r of the circle; the offset within 1e-6 of S + d n.
    CHECK(worst <= 1e-6 + 1e-8);
  }
  CHECK_THROWS_AS(construct::offset_surface(c, 0.0), Error);
}

TEST_CASE("an offset refuses a collapsed edge (no normal)", "[construct][patches]") {
  // A triangle-like patch: its whole v = 0 row is one point.
  const Surface apex = bezier([](int i, int j) {
    const double rho = j / 3.0, a = i / 3.0 * M_PI / 2;
    return std::array<double, 3>{rho * std::cos(a), rho * std::sin(a), 0.0};
  });
  try {
    (void)construct::offset_surface(apex, 0.1);
    FAIL("no error");
  } catch (const Error& e) {
    CHECK_THAT(e.what(), Catch::Contains("singular"));
  }
}

TEST_CASE("the solid of a cylinder's tube: five valid cells of volume pi r^2 h", "[construct][tube]") {
  const double r = 2.0, h = 3.0;
  const auto cells = construct::tube_solid(cylinder(r, h), 0.5);
  REQUIRE(cells.size() == 5);
  CHECK(cells[0].part == "core");
  double volume = 0.0;
  for (const auto& c : cells) {
    const auto v = geom::check_validity(c.volume);
    INFO(c.part << ": det J in [" << v.min_bound << ", " << v.max_bound << "]");
    CHECK(v.verdict == geom::Validity::valid);
    CHECK(v.orientation == 1);
    volume += geom::volume(c.volume);
  }
  // The core is the square of half-diagonal r / 2: area (r / sqrt 2)^2 = r^2 / 2.
  CHECK(geom::volume(cells[0].volume) == Approx(r * r / 2 * h).epsilon(1e-12));
  CHECK(volume == Approx(M_PI * r * r * h).epsilon(1e-8));
  // Outer faces: s_k's w = 1 face is on the cylinder.
  for (std::size_t k = 1; k < 5; ++k) {
    const auto x = cells[k].volume.eval({0.3, 0.6, 1.0});
    CHECK(std::hypot(x[0], x[1]) == Approx(r).epsilon(1e-8));
  }
  // A surface not closed in u is not a tube.
  const Surface whole = cylinder(r, h);
  const Surface open = spline::restrict_to(whole, 0, whole.domain(0)[0], 0.5 * (whole.domain(0)[0] + whole.domain(0)[1]));
  CHECK_THROWS_AS(construct::tube_solid(open), Error);
  CHECK_THROWS_AS(construct::tube_solid(cylinder(r, h), 1.5), Error);
}
