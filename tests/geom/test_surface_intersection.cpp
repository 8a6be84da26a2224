// Surface-surface intersection (geom/surface_intersection.hpp). Truths: a plane through a sphere
// (of revolution, within 1e-10 of the exact one) meets it in the circle of radius sqrt(1 - h^2)
// at height h, one closed component; two planes meet in a segment that ends on the first
// patch's boundary; a plane through a cylinder's axis cuts it in two lines; disjoint surfaces
// have no intersection. Every point lies on both surfaces within the tolerance.
#include <catch2/catch.hpp>

#include <cmath>

#include "trivox/construct/constructors.hpp"
#include "trivox/geom/surface_intersection.hpp"
#include "intersection_fixtures.hpp"

using namespace trivox;
using spline::KnotVector;
using spline::Surface;

namespace {

using test::plane_patch;
using test::unit_sphere;

void check_on_both(const Surface& a, const Surface& b, const geom::IntersectionCurve& c, double tol) {
  for (const auto& p : c.points) {
    const auto x = a.eval(p.uv1), y = b.eval(p.uv2);
    CHECK(std::hypot(x[0] - p.xyz[0], x[1] - p.xyz[1], x[2] - p.xyz[2]) < tol);
    CHECK(std::hypot(y[0] - p.xyz[0], y[1] - p.xyz[1], y[2] - p.xyz[2]) < tol);
  }
}

}  // namespace

TEST_CASE("a plane cuts a sphere in one closed circle", "[intersection]") {
  const Surface sphere = unit_sphere();
  const double h = 0.3;
  const Surface plane = plane_patch({-2, -2, h}, {4, 0, 0}, {0, 4, 0});
  const auto curves = geom::intersect_surfaces(sphere, plane);
  REQUIRE(curves.size() == 1);
  const auto& c = curves[0];
  // The circle crosses the sphere's seam (the revolution's start and end): open in parameter
  // space, from one side of the seam to the other, closed in xyz.
  CHECK_FALSE(c.closed);
  CHECK(std::abs(c.points.front().uv1[1] - c.points.back().uv1[1]) == Approx(1.0).margin(1e-12));
  CHECK(c.points.size() > 20);
  check_on_both(sphere, plane, c, 1e-9);
  const double R = std::sqrt(1 - h * h);
  for (const auto& p : c.points) {
    CHECK(std::hypot(p.xyz[0], p.xyz[1]) == Approx(R).margin(1e-8));
    CHECK(p.xyz[2] == Approx(h).margin(1e-9));
  }
  // The fitted curves: xyz on the circle, and the parameter curves map onto it.
  for (int i = 0; i <= 400; ++i) {
    const double t = i / 400.0;
    const auto x = c.xyz.eval({t});
    CHECK(std::hypot(x[0], x[1]) == Approx(R).margin(1e-7));
    CHECK(x[2] == Approx(h).margin(1e-7));
    const auto u1 = c.uv1.eval({t});
    const auto y = sphere.eval({u1[0], u1[1]});
    CHECK(std::hypot(y[0] - x[0], y[1] - x[1], y[2] - x[2]) < 1e-6);
  }
  // Its ends coincide in xyz.
  const auto e0 = c.xyz.eval({0.0}), e1 = c.xyz.eval({1.0});
  CHECK(std::hypot(e0[0] - e1[0], e0[1] - e1[1], e0[2] - e1[2]) < 1e-9);
  // Away from the seam the same circle is a closed component: a patch of the plane inside the
  // sphere's parameter range, cut by a quarter of the sphere (no seam) gives an open arc; the
  // full sphere rotated so the circle avoids the seam gives a closed one.
  const Surface tilted = plane_patch({-2, -2, -2}, {4, 0, 0}, {0, 0, 4});  // y = -2: misses
  CHECK(geom::intersect_surfaces(sphere, tilted).empty());
  const Surface vertical = plane_patch({-2, 0.5, -2}, {4, 0, 0}, {0, 0, 4});  // y = 0.5: no seam crossing
  const auto loop = geom::intersect_surfaces(sphere, vertical);
  REQUIRE(loop.size() == 1);
  CHECK(loop[0].closed);
  check_on_both(sphere, vertical, loop[0], 1e-9);
  for (const auto& p : loop[0].points) CHECK(std::hypot(p.xyz[0], p.xyz[2]) == Approx(std::sqrt(0.75)).margin(1e-8));
  for (int i = 0; i <= 200; ++i) {
    const auto x = loop[0].xyz.eval({i / 200.0});
    CHECK(std::hypot(x[0], x[2]) == Approx(std::sqrt(0.75)).margin(1e-7));
    CHECK(x[1] == Approx(0.5).margin(1e-7));
  }
}

TEST_CASE("open and multiple components, and none", "[intersection]") {
  // z = 0 over [0,1]^2 and the plane x = 0.5 (y in [-1, 2], z in [-1, 1]): the segment
  // x = 0.5, z = 0, y in [0, 1], ending on the first patch's edges.
  const Surface a = plane_patch({0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  const Surface b = plane_patch({0.5, -1, -1}, {0, 3, 0}, {0, 0, 2});
  const auto seg = geom::intersect_surfaces(a, b);
  REQUIRE(seg.size() == 1);
  CHECK_FALSE(seg[0].closed);
  check_on_both(a, b, seg[0], 1e-9);
  const auto& f = seg[0].points.front();
  const auto& l = seg[0].points.back();
  CHECK(std::min(f.xyz[1], l.xyz[1]) == Approx(0.0).margin(1e-9));
  CHECK(std::max(f.xyz[1], l.xyz[1]) == Approx(1.0).margin(1e-9));
  for (const auto& p : seg[0].points) {
    CHECK(p.xyz[0] == Approx(0.5).margin(1e-9));
    CHECK(p.xyz[2] == Approx(0.0).margin(1e-9));
  }
  // A cylinder x^2 + y^2 = 4, z in [0, 3] and the plane y = 0 through its axis: two lines.
  spline::Curve line({KnotVector::bezier(2)}, 3, std::vector<double>{2, 0, 0, 2, 0, 3});
  construct::Revolution rev;
  rev.relative_tolerance = 1e-11;
  const Surface cyl = construct::revolve(line, rev);
  const Surface cut = plane_patch({-3, 0, -1}, {6, 0, 0}, {0, 0, 5});
  const auto two = geom::intersect_surfaces(cyl, cut);
  REQUIRE(two.size() == 2);
  double xs[2];
  for (int k = 0; k < 2; ++k) {
    CHECK_FALSE(two[k].closed);
    check_on_both(cyl, cut, two[k], 1e-9);
    xs[k] = two[k].points.front().xyz[0];
    for (const auto& p : two[k].points) CHECK(std::abs(p.xyz[0]) == Approx(2.0).margin(1e-8));
    const double z0 = two[k].points.front().xyz[2], z1 = two[k].points.back().xyz[2];
    CHECK(std::min(z0, z1) == Approx(0.0).margin(1e-9));
    CHECK(std::max(z0, z1) == Approx(3.0).margin(1e-9));
  }
  CHECK(xs[0] * xs[1] < 0);  // one on each side
  // Disjoint.
  CHECK(geom::intersect_surfaces(a, plane_patch({0, 0, 1}, {1, 0, 0}, {0, 1, 0})).empty());
}
