// Closest points on surfaces (geom/closest_point.hpp). Truths: the distance to a planar patch
// (perpendicular inside, to the nearest edge or corner outside); to a cylinder of revolution
// |r - R| within its height (the revolution is within 1e-10 R of the exact circle); the
// returned point lies on the surface and the residual is normal to it (Eq. 3
// of Massarwi & Elber 2016).
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "trivox/construct/constructors.hpp"
#include "trivox/geom/closest_point.hpp"

using namespace trivox;
using spline::KnotVector;

TEST_CASE("closest points on a planar patch and a cylinder", "[closest_point]") {
  // The square [0,2] x [0,1] at z = 0, as a biquadratic (so evaluation is not trivially linear).
  std::vector<double> pts;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) pts.insert(pts.end(), {i * 1.0, j * 0.5, 0.0});
  const geom::SurfaceDistance plane(spline::Surface({KnotVector::bezier(3), KnotVector::bezier(3)}, 3, pts));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1.0, 3.0);
  for (int n = 0; n < 500; ++n) {
    const std::array<double, 3> p{U(rng), U(rng) - 0.5, U(rng) - 1.0};
    const double dx = std::max({0.0, -p[0], p[0] - 2}), dy = std::max({0.0, -p[1], p[1] - 1});
    const double expect = std::sqrt(dx * dx + dy * dy + p[2] * p[2]);
    const auto c = plane.closest(p);
    CHECK(c.distance == Approx(expect).margin(1e-10));
  }
  // Cylinder x^2 + y^2 = 4, 0 <= z <= 3: a line revolved about z.
  spline::Curve line({KnotVector::bezier(2)}, 3, std::vector<double>{2, 0, 0, 2, 0, 3});
  construct::Revolution rev;
  rev.relative_tolerance = 1e-10;
  const spline::Surface cyl = construct::revolve(line, rev);
  const geom::SurfaceDistance cd(cyl);
  for (int n = 0; n < 300; ++n) {
    const double r = std::uniform_real_distribution<double>(0.2, 4.0)(rng);
    const double a = std::uniform_real_distribution<double>(0, 6.283)(rng);
    const double z = std::uniform_real_distribution<double>(0.1, 2.9)(rng);
    const std::array<double, 3> p{r * std::cos(a), r * std::sin(a), z};
    const auto c = cd.closest(p);
    CHECK(c.distance == Approx(std::abs(r - 2)).margin(1e-8));
    // The foot is on the surface and the residual is normal to it.
    const auto d = cyl.eval_derivatives(c.uv, 1);
    CHECK(std::hypot(d[0] - c.point[0], d[1] - c.point[1], d[2] - c.point[2]) < 1e-12);
    const double rr[3] = {p[0] - c.point[0], p[1] - c.point[1], p[2] - c.point[2]};
    CHECK(std::abs(rr[0] * d[3] + rr[1] * d[4] + rr[2] * d[5]) < 1e-7 * (1 + c.distance) * std::hypot(d[3], d[4], d[5]));
  }
}

TEST_CASE("warm-started closest points agree with cold ones", "[closest_point]") {
  // Along a walk of nearby points, Newton from the previous answer's (u, v) reaches the cold
  // query's point: same distance, same parameters to rounding.
  spline::Curve line({KnotVector::bezier(2)}, 3, std::vector<double>{2, 0, 0, 2, 0, 3});
  construct::Revolution rev;
  rev.relative_tolerance = 1e-10;
  const geom::SurfaceDistance cd(construct::revolve(line, rev));
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::array<double, 3> p{3.0, 0.5, 1.0};
  auto prev = cd.closest(p);
  double worst_d = 0.0, worst_uv = 0.0;
  for (int n = 0; n < 2000; ++n) {
    p = {p[0] + 0.02 * U(rng), p[1] + 0.02 * U(rng), std::clamp(p[2] + 0.02 * U(rng), 0.2, 2.8)};
    std::vector<double> values(3);
    const auto w = cd.closest(p, prev.uv, values.data());
    const auto c = cd.closest(p);
    CHECK(w.converged);
    worst_d = std::max(worst_d, std::abs(w.distance - c.distance));
    worst_uv = std::max({worst_uv, std::abs(w.uv[0] - c.uv[0]), std::abs(w.uv[1] - c.uv[1])});
    CHECK(values == std::vector<double>(w.point.begin(), w.point.end()));
    prev = w;
  }
  CHECK(worst_d < 1e-13);
  CHECK(worst_uv < 1e-11);
  // A start outside the domain is clamped into it.
  const auto c = cd.closest({3.0, 0.0, 1.0}, {-5.0, 9.0});
  CHECK(c.distance == Approx(1.0).margin(1e-8));
}
