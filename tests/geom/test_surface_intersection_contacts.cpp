// Surface-surface intersection where surfaces meet at single points or touch
// (geom/surface_intersection.hpp). Truths:
// - two planes whose line of intersection passes through a corner of the first patch only meet in
//   that one point: no curve (a point bounds nothing), and no error;
// - faces of two cells of construct's 7-cell ball that meet only along the edge they share (the
//   cube's bottom and the x0 cap's inner face, x = z = -0.45) give curves on that edge only, each
//   with at least 2 points (the marching there leaves both rectangles at once, and branches
//   that shrank to one point made the curve fit throw before);
// - a plane through the poles of a sphere of revolution (whose parametrisation is singular
//   there) cuts it in a great circle: every curve returned lies on both surfaces, has at least 2
//   points and its fitted curves, and the curves' total length is the circle's 2 pi up to the
//   short gaps where the marching stops at a pole;
// - contacts, classified by the surfaces' second-order contact: the plane z = 0 touches the
//   paraboloid z = x^2 + y^2 at the origin alone (point: no curve); z = 0 and the trough
//   z = (x - 2)^2 touch along the line x = 2 (curve, reported as a contact); two overlapping
//   patches of one plane coincide (region).
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>

#include "trivox/construct/constructors.hpp"
#include "trivox/construct/primitives.hpp"
#include "trivox/geom/surface_intersection.hpp"
#include "intersection_fixtures.hpp"
#include "trivox/spline/extract.hpp"

using namespace trivox;
using spline::KnotVector;
using spline::Surface;

namespace {

using test::plane_patch;
using test::unit_sphere;

double distance(const std::vector<double>& x, const std::array<double, 3>& y) {
  return std::hypot(x[0] - y[0], x[1] - y[1], x[2] - y[2]);
}

}  // namespace

TEST_CASE("planes meeting at one corner point give no curve", "[intersection][contacts]") {
  // a = [0, 1]^2 x {0}; b is the plane x + y = 0, which meets a only at the origin.
  const Surface a = plane_patch({0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  const Surface b = plane_patch({-1, 1, -1}, {2, -2, 0}, {0, 0, 2});
  std::vector<geom::IntersectionContact> contacts;
  std::vector<geom::IntersectionCurve> curves;
  REQUIRE_NOTHROW(curves = geom::intersect_surfaces(a, b, {}, &contacts));
  CHECK(curves.empty());
  // The planes cross transversally: no tangential contact either.
  CHECK(contacts.empty());
  // The same with the roles swapped; and the plane x + y = 1, through a's corners (1, 0) and
  // (0, 1), cuts it along its diagonal: a proper curve.
  REQUIRE_NOTHROW(curves = geom::intersect_surfaces(b, a));
  CHECK(curves.empty());
  const Surface diag = plane_patch({0, 1, -1}, {2, -2, 0}, {0, 0, 2});
  curves = geom::intersect_surfaces(a, diag);
  REQUIRE(curves.size() == 1);
  CHECK(curves[0].points.size() >= 2);
  CHECK(distance(curves[0].xyz.eval({0.0}), curves[0].points.front().xyz) < 1e-12);
}

TEST_CASE("faces of two ball cells meeting along an edge", "[intersection][contacts]") {
  const auto cells = construct::build_primitive("S", construct::Sphere{{0, 0, 0}, 1});
  auto cell = [&](const std::string& n) {
    for (const auto& c : cells)
      if (c.name == n) return c.volume;
    FAIL("no cell " << n);
    return cells[0].volume;
  };
  const Surface a = spline::boundary_face(cell("S.core"), spline::Face::w0);
  const Surface b = spline::boundary_face(cell("S.x0"), spline::Face::w0);
  std::vector<geom::IntersectionCurve> curves;
  REQUIRE_NOTHROW(curves = geom::intersect_surfaces(a, b, {.tolerance = 1e-10}));
  CHECK(!curves.empty());
  for (const auto& c : curves) {
    REQUIRE(c.points.size() >= 2);
    CHECK(c.xyz.dim() == 3);
    for (const auto& p : c.points) {
      CHECK(distance(a.eval(p.uv1), p.xyz) < 1e-9);
      CHECK(distance(b.eval(p.uv2), p.xyz) < 1e-9);
      CHECK(std::abs(p.xyz[0] + 0.45) < 1e-9);
      CHECK(std::abs(p.xyz[2] + 0.45) < 1e-9);
      CHECK(std::abs(p.xyz[1]) <= 0.45 + 1e-9);
    }
  }
}

TEST_CASE("a plane through a sphere's poles", "[intersection][contacts]") {
  const Surface sphere = unit_sphere();
  const Surface plane = plane_patch({0, -2, -2}, {0, 4, 0}, {0, 0, 4});  // x = 0
  std::vector<geom::IntersectionCurve> curves;
  REQUIRE_NOTHROW(curves = geom::intersect_surfaces(sphere, plane));
  REQUIRE(!curves.empty());
  double length = 0;
  for (const auto& c : curves) {
    REQUIRE(c.points.size() >= 2);
    REQUIRE(c.xyz.dim() == 3);
    for (std::size_t i = 0; i < c.points.size(); ++i) {
      const auto& p = c.points[i];
      CHECK(distance(sphere.eval(p.uv1), p.xyz) < 1e-9);
      CHECK(distance(plane.eval(p.uv2), p.xyz) < 1e-9);
      CHECK(std::abs(p.xyz[0]) < 1e-9);
      if (i + 1 < c.points.size()) {
        // Chords of the unit circle: 2 asin(d / 2) is the arc between them.
        const auto& q = c.points[i + 1];
        const double d = std::hypot(q.xyz[0] - p.xyz[0], q.xyz[1] - p.xyz[1], q.xyz[2] - p.xyz[2]);
        length += 2 * std::asin(std::min(1.0, d / 2));
      }
    }
    if (c.closed) {
      const auto &p = c.points.back(), &q = c.points.front();
      length += 2 * std::asin(std::min(1.0, std::hypot(q.xyz[0] - p.xyz[0], q.xyz[1] - p.xyz[1], q.xyz[2] - p.xyz[2]) / 2));
    }
  }
  std::printf("plane through the poles: %zu curves, length %.12g (2 pi = %.12g)\n", curves.size(), length, 2 * M_PI);
  CHECK(length <= 2 * M_PI + 1e-9);
  CHECK(length >= 2 * M_PI - 1e-3);
}

TEST_CASE("tangential contacts are classified", "[intersection][contacts]") {
  const Surface sphere = unit_sphere();
  // Point: z = 0 touches the paraboloid z = x^2 + y^2 (biquadratic, exact) at the origin alone.
  {
    const std::vector<double> z{1, -1, 1};
    std::vector<double> pts;
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) pts.insert(pts.end(), {-1.0 + i, -1.0 + j, z[static_cast<std::size_t>(i)] + z[static_cast<std::size_t>(j)]});
    const Surface bowl({KnotVector::bezier(3), KnotVector::bezier(3)}, 3, pts);
    const Surface floor = plane_patch({-2, -2, 0}, {4, 0, 0}, {0, 4, 0});
    std::vector<geom::IntersectionContact> contacts;
    const auto curves = geom::intersect_surfaces(floor, bowl, {}, &contacts);
    std::printf("plane tangent to a paraboloid: %zu curves, %zu contacts\n", curves.size(), contacts.size());
    CHECK(curves.empty());
    for (const auto& k : contacts) {
      CHECK(k.kind == geom::IntersectionContact::Kind::point);
      CHECK(std::hypot(k.at.xyz[0], k.at.xyz[1], k.at.xyz[2]) < 1e-4);
    }
  }
  // Curve: z = 0 and the trough z = (x - 2)^2 over [1, 3] x [0, 4].
  {
    const Surface floor = plane_patch({0, 0, 0}, {4, 0, 0}, {0, 4, 0});
    const Surface trough({KnotVector::bezier(3), KnotVector::bezier(2)}, 3,
                         std::vector<double>{1, 0, 1, 2, 0, -1, 3, 0, 1, 1, 4, 1, 2, 4, -1, 3, 4, 1});
    std::vector<geom::IntersectionContact> contacts;
    const auto curves = geom::intersect_surfaces(floor, trough, {}, &contacts);
    std::printf("plane and trough: %zu curves, %zu contacts\n", curves.size(), contacts.size());
    REQUIRE(!contacts.empty());
    for (const auto& k : contacts) {
      CHECK(k.kind == geom::IntersectionContact::Kind::curve);
      CHECK(std::abs(k.at.xyz[0] - 2) < 1e-4);
      CHECK(std::abs(k.at.xyz[2]) < 1e-8);
    }
  }
  // Region: two overlapping patches of the plane z = 0.
  {
    std::vector<geom::IntersectionContact> contacts;
    const auto curves = geom::intersect_surfaces(plane_patch({0, 0, 0}, {1, 0, 0}, {0, 1, 0}),
                                                 plane_patch({0.5, 0.25, 0}, {1, 0, 0}, {0, 1, 0}), {}, &contacts);
    CHECK(curves.empty());
    REQUIRE(!contacts.empty());
    for (const auto& k : contacts) CHECK(k.kind == geom::IntersectionContact::Kind::region);
  }
}
