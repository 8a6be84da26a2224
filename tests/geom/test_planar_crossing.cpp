// Crossings of planar curves (geom/planar_crossing.hpp). Truths: a square's four sides meet only
// at shared corners; two diagonals cross at the centre; a cubic whose control polygon loops
// crosses itself (at the point where the two parameter values map to one point, checked by
// evaluating both); a closed circle's seam is not a crossing.
#include <catch2/catch.hpp>

#include <cmath>

#include "trivox/construct/constructors.hpp"
#include "trivox/geom/planar_crossing.hpp"

using namespace trivox;
using spline::Curve;
using spline::KnotVector;

namespace {
Curve line(double x0, double y0, double x1, double y1) {
  return Curve({KnotVector::bezier(2)}, 2, std::vector<double>{x0, y0, x1, y1});
}
}  // namespace

TEST_CASE("planar crossings: corners allowed, crossings found", "[crossing]") {
  const Curve square[4] = {line(0, 0, 1, 0), line(0, 1, 1, 1), line(0, 0, 0, 1), line(1, 0, 1, 1)};
  CHECK_FALSE(geom::first_crossing(square, 1e-6));
  const Curve diagonals[2] = {line(0, 0, 1, 1), line(0, 1, 1, 0)};
  const auto x = geom::first_crossing(diagonals, 1e-6);
  REQUIRE(x);
  CHECK(x->curve_a == 0);
  CHECK(x->curve_b == 1);
  CHECK(x->point[0] == Approx(0.5).margin(1e-9));
  CHECK(x->point[1] == Approx(0.5).margin(1e-9));
  // A cubic with a loop: P0 (0,0), P1 (3,2), P2 (-2,2), P3 (1,0) (symmetric about x = 0.5).
  const Curve loop({KnotVector::bezier(4)}, 2, std::vector<double>{0, 0, 3, 2, -2, 2, 1, 0});
  const Curve one[1] = {loop};
  const auto s = geom::first_crossing(one, 1e-7);
  REQUIRE(s);
  CHECK(s->curve_a == 0);
  CHECK(s->curve_b == 0);
  const auto pa = loop.eval({s->t_a}), pb = loop.eval({s->t_b});
  CHECK(std::abs(s->t_a - s->t_b) > 0.1);
  CHECK(std::hypot(pa[0] - pb[0], pa[1] - pb[1]) < 1e-5);
  CHECK(s->point[0] == Approx(0.5).margin(1e-5));  // on the axis of symmetry
  // A closed circle: its seam is shared by its own ends.
  const Curve arc = construct::circle_arc(2 * M_PI, 1e-8);
  const Curve c1[1] = {arc};
  CHECK_FALSE(geom::first_crossing(c1, 1e-6));
}
