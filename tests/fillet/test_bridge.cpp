// Flends between disjoint bodies (Eager & Dannenhoffer 2019, Sec. III), volumetric: the bridge
// between two faces. Truths: between aligned boxes the bridge is the box between them (volume 1 for
// any dip); with the second box lifted by 1 the end lines are parallel and the section's bottom and
// top edges are translates, so the cross-section has area 1 x 2 (volume 2); the bridge's end faces
// are the cells' faces point for point, its w-direction there is the cells' own (G1), properties
// run from one cell's to the other's.
#include <catch2/catch.hpp>

#include <cmath>

#include "trivox/construct/primitives.hpp"
#include "trivox/fillet/bridge.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/spline/extract.hpp"

#include "corner.hpp"

using namespace trivox;
using spline::Face;
using spline::Trivariate;
const auto box = fillet_test::box_cell;  // tests/fillet/corner.hpp

namespace {

double angle_to(const Trivariate& t, double u, double v, double w, std::array<double, 3> dir) {
  const auto d = t.eval_derivatives({u, v, w}, 1);
  const std::size_t k = static_cast<std::size_t>(t.dim());
  const double x = d[3 * k], y = d[3 * k + 1], z = d[3 * k + 2];
  const double c = (x * dir[0] + y * dir[1] + z * dir[2]) / std::sqrt(x * x + y * y + z * z);
  return std::acos(std::clamp(std::abs(c), -1.0, 1.0));
}

}  // namespace

TEST_CASE("the bridge between aligned boxes is the box between them, for any dip", "[fillet][bridge]") {
  const Trivariate a = box({0, 0, 0}, {1, 1, 1}, 0.0), b = box({2, 0, 0}, {3, 1, 1}, 1.0);
  for (double dip : {0.0, 0.3, 1.0}) {
    INFO("dip " << dip);
    fillet::BridgeOptions o;
    o.dip = dip;
    fillet::BridgeQuality q;
    const Trivariate t = fillet::bridge(a, Face::u1, b, Face::u0, o, &q);
    CHECK(geom::volume(t) == Approx(1.0).epsilon(1e-12));
    CHECK(q.det_min > 0.0);
    for (double u : {0.0, 0.3, 1.0})
      for (double v : {0.0, 0.6, 1.0}) {
        const auto p0 = t.eval({u, v, 0.0}), p1 = t.eval({u, v, 1.0});
        CHECK(p0[0] == Approx(1.0).margin(1e-14));
        CHECK(p1[0] == Approx(2.0).margin(1e-14));
        CHECK(p0[3] == Approx(0.0).margin(1e-14));
        CHECK(p1[3] == Approx(1.0).margin(1e-14));
        if (dip > 0.0) {
          CHECK(angle_to(t, u, v, 0.0, {1, 0, 0}) < 1e-12);
          CHECK(angle_to(t, u, v, 1.0, {1, 0, 0}) < 1e-12);
        }
      }
  }
}

TEST_CASE("a bridge to a lifted box: parallel end lines, translated edges", "[fillet][bridge]") {
  const Trivariate a = box({0, 0, 0}, {1, 1, 1}, 0.2), b = box({3, 0, 1}, {4, 1, 2}, 0.8);
  fillet::BridgeQuality q;
  const Trivariate t = fillet::bridge(a, Face::u1, b, Face::u0, {}, &q);
  CHECK(geom::volume(t) == Approx(2.0).epsilon(1e-10));
  CHECK(q.det_min > 0.0);
  CHECK(q.g1_angle[0] < 1e-9);
  CHECK(q.g1_angle[1] < 1e-9);
  // Properties run from 0.2 to 0.8 and stay between.
  for (double w = 0.0; w <= 1.0; w += 0.125) {
    const double g = t.eval({0.5, 0.5, w})[3];
    CHECK(g >= 0.2 - 1e-14);
    CHECK(g <= 0.8 + 1e-14);
  }
}

TEST_CASE("bridges between two cylinders' end disks: the disk swept, G1 with both", "[fillet][bridge]") {
  // A stands on z = 0 up to z = 5; B, shifted by 1 in x, from z = 8 up. Every section is the same
  // curve translated, so horizontal slices are disks: the volume is pi r^2 times the height 3.
  const double r = 2.0;
  auto lower = construct::build_primitive("a", construct::Cylinder{{0, 0, 0}, {0, 0, 1}, r, 5.0});
  auto upper = construct::build_primitive("b", construct::Cylinder{{1, 0, 8}, {0, 0, 1}, r, 5.0});
  double volume = 0.0, disks = 0.0;
  for (std::size_t i = 0; i < lower.size(); ++i) {
    INFO(lower[i].name);
    fillet::BridgeQuality q;
    const Trivariate t = fillet::bridge(lower[i].volume, Face::w1, upper[i].volume, Face::w0, {}, &q);
    CHECK(q.orientation == "as is");
    CHECK(q.det_min > 0.0);
    CHECK(q.g1_angle[0] < 1e-9);
    CHECK(q.g1_angle[1] < 1e-9);
    volume += geom::volume(t);
    disks += geom::volume(lower[i].volume) / 5.0;  // the cells' own cross-section area
    // The bridge's end faces are the cells' faces, point for point.
    const auto fa = spline::boundary_face(lower[i].volume, Face::w1);
    for (double u : {0.0, 0.4, 1.0})
      for (double v : {0.0, 0.7, 1.0}) {
        const auto p = t.eval({u, v, 0.0}), e = fa.eval({u, v});
        CHECK(std::hypot(p[0] - e[0], p[1] - e[1], p[2] - e[2]) < 1e-12);
        CHECK(angle_to(t, u, v, 0.0, {0, 0, 1}) < 1e-9);
        CHECK(angle_to(t, u, v, 1.0, {0, 0, 1}) < 1e-9);
      }
  }
  CHECK(volume == Approx(3.0 * disks).epsilon(1e-10));
  CHECK(volume == Approx(3.0 * M_PI * r * r).epsilon(2e-4));

  const Trivariate& a = lower[0].volume;
  CHECK_THROWS_WITH(fillet::bridge(a, Face::w1, upper[0].volume, Face::w0, {.dip = 1.5}),
                    Catch::Contains("dip 1.5; expected"));
  // Faces that meet are a fillet's, not a bridge's; faces that look away do not bridge.
  auto crossing = construct::build_primitive("c", construct::Cylinder{{0, 0, 5}, {1, 0, 1}, 1.0, 5.0});
  CHECK_THROWS_WITH(fillet::bridge(a, Face::w1, crossing[0].volume, Face::w0), Catch::Contains("the faces meet"));
  auto below = construct::build_primitive("d", construct::Cylinder{{0, 0, -9}, {0, 0, 1}, r, 5.0});
  CHECK_THROWS_WITH(fillet::bridge(a, Face::w1, below[0].volume, Face::w1),
                    Catch::Contains("do not face each other"));
}
