// Rail curves (fillet/rails.hpp). Truths from elementary geometry:
//  - a floor z = 0 and a wall x = 2 meet in the line x = 2, z = 0; the rails are the lines
//    x = 2 + d1 on the floor and z = d2 on the wall (exactly, planes being linear), each on the
//    side outside the other cell; a flip mirrors them; too large a distance leaves the face;
//  - a cylinder of radius r on a floor: the floor rail is the circle of radius r + d1 (r - d1
//    flipped), the cylinder rail the circle z = d2;
//  - a vertical plane y = 1/2 through the unit sphere: C is a closed circle of radius sqrt(3)/2;
//    the plane rail is the circle of radius sqrt(3)/2 + d1, the sphere rail the circle at
//    latitude pi/6 - 2 asin(d2 / 2) (C's normal planes contain the sphere's centre);
//  - a tilted plane through a cylinder (an ellipse): no closed form; every rail point is at
//    distance d from C and in C's normal plane;
//  - the parabola y = x^2 (radius of curvature 1/2 at its apex) as a wall on a floor, offset on
//    the floor into its concave side by d = 0.8 > 1/2: the offset has a swallowtail whose
//    crossing is at x = 0, y = (4 d^2 - 1) / 4 + 1/2, reached from C at x = +-sqrt(4 d^2 - 1) / 2.
// Generic checks at random t: both bases map to one point C(t) (within the tolerance), every
// rail point is at distance d from C(t) and in its normal plane, all four curves share one
// function space on [0, 1].
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "trivox/construct/constructors.hpp"
#include "trivox/error.hpp"
#include "trivox/fillet/rails.hpp"
#include "trivox/geom/planar_crossing.hpp"
#include "trivox/spline/refine.hpp"

using namespace trivox;
using spline::Curve;
using spline::KnotVector;
using spline::Surface;
using P3 = std::array<double, 3>;

namespace {

Surface plane_patch(P3 o, P3 e1, P3 e2) {
  std::vector<double> pts;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i)
      for (std::size_t d = 0; d < 3; ++d) pts.push_back(o[d] + i * e1[d] + j * e2[d]);
  return Surface({KnotVector::bezier(2), KnotVector::bezier(2)}, 3, pts);
}

/// Its seam (the revolution's start) is the line x = 0, y = r.
Surface cylinder(double r, double z0, double z1) {
  Curve line({KnotVector::bezier(2)}, 3, std::vector<double>{0, r, z0, 0, r, z1});
  construct::Revolution rev;
  rev.relative_tolerance = 1e-11;
  return construct::revolve(line, rev);
}

Surface unit_sphere() {
  // Within 1e-9 of the unit sphere (finer costs the intersection seconds: more pieces).
  const auto arc = construct::circle_arc(M_PI, 1e-9);
  std::vector<double> pts;
  for (int i = 0; i < arc.size(); ++i) pts.insert(pts.end(), {arc.point(i)[1], 0.0, arc.point(i)[0]});
  construct::Revolution r;
  r.relative_tolerance = 1e-9;
  return construct::revolve(spline::Curve(arc.knot_vectors(), 3, pts), r);
}

P3 sub(const P3& a, const P3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const P3& a, const P3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const P3& a) { return std::sqrt(dot(a, a)); }
P3 cross(const P3& a, const P3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

P3 point(const Surface& s, const Curve& c, double t) {
  const auto uv = c.eval({t});
  const auto x = s.eval({uv[0], uv[1]});
  return {x[0], x[1], x[2]};
}

P3 normal(const Surface& s, const Curve& c, double t) {
  const auto uv = c.eval({t});
  const auto d = s.eval_derivatives({uv[0], uv[1]}, 1);
  const int k = s.dim();
  return cross({d[k], d[k + 1], d[k + 2]}, {d[2 * k], d[2 * k + 1], d[2 * k + 2]});
}

/// +1 when the face's S_u x S_v at its parameter centre points away from `inside`.
double outward_from(const Surface& s, const P3& inside) {
  const double u = 0.5 * (s.domain(0)[0] + s.domain(0)[1]), v = 0.5 * (s.domain(1)[0] + s.domain(1)[1]);
  const auto d = s.eval_derivatives({u, v}, 1);
  const int k = s.dim();
  const P3 n = cross({d[k], d[k + 1], d[k + 2]}, {d[2 * k], d[2 * k + 1], d[2 * k + 2]});
  return dot(n, sub({d[0], d[1], d[2]}, inside)) > 0 ? 1.0 : -1.0;
}

bool in_trim(const fillet::Rail& r, double t) {
  for (const auto& m : r.trimmed)
    if (t >= m[0] && t <= m[1]) return true;
  return false;
}

/// The generic properties, at `count` random t. Returns the largest deviation seen.
double check_generic(const Surface& f1, const Surface& f2, const fillet::RailPair& rp, std::array<double, 2> d,
                     double tol, int count = 1000) {
  // One function space on [0, 1], cubic.
  const auto& kv = rp.rails[0].base.knots(0);
  CHECK(kv.order() == 4);
  CHECK(kv.front() == 0.0);
  CHECK(kv.back() == 1.0);
  for (const auto& r : rp.rails) {
    CHECK(r.base.knots(0) == kv);
    CHECK(r.rail.knots(0) == kv);
    CHECK(r.max_error <= tol);
  }
  const Surface* faces[2] = {&f1, &f2};
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  double worst = 0.0;
  for (int k = 0; k < count; ++k) {
    const double t = k == 0 ? 0.0 : k == 1 ? 1.0 : U(rng);
    const P3 c1 = point(f1, rp.rails[0].base, t), c2 = point(f2, rp.rails[1].base, t);
    const double gap = norm(sub(c1, c2));
    CHECK(gap <= tol);
    worst = std::max(worst, gap);
    P3 T = cross(normal(f1, rp.rails[0].base, t), normal(f2, rp.rails[1].base, t));
    const double len = norm(T);
    T = {T[0] / len, T[1] / len, T[2] / len};
    for (std::size_t i = 0; i < 2; ++i) {
      if (in_trim(rp.rails[i], t)) continue;
      const P3 e = sub(point(*faces[i], rp.rails[i].rail, t), c1);
      const double ed = std::abs(norm(e) - d[i]), en = std::abs(dot(e, T));
      CHECK(ed <= tol);
      CHECK(en <= tol);
      worst = std::max({worst, ed, en});
    }
  }
  return worst;
}

}  // namespace

TEST_CASE("perpendicular planes: rails are the lines x = 2 + d1 and z = d2", "[rails]") {
  // The floor cell lies below z = 0 (normal +z, outward), the wall cell at x < 2 (normal +x).
  const Surface floor = plane_patch({0, 0, 0}, {4, 0, 0}, {0, 4, 0});
  const Surface wall = plane_patch({2, -1, -1}, {0, 6, 0}, {0, 0, 5});
  const auto curves = geom::intersect_surfaces(floor, wall);
  REQUIRE(curves.size() == 1);
  const double d1 = 0.5, d2 = 0.75;
  const std::array<double, 2> d{d1, d2};
  const auto rp = fillet::offset_rails(floor, wall, {1, 1}, curves[0], d);
  CHECK_FALSE(rp.closed);
  for (const auto& r : rp.rails) CHECK(r.trimmed.empty());
  check_generic(floor, wall, rp, d, 1e-7);
  for (int k = 0; k <= 200; ++k) {
    const double t = k / 200.0;
    const P3 c = point(floor, rp.rails[0].base, t);
    const P3 a = point(floor, rp.rails[0].rail, t), b = point(wall, rp.rails[1].rail, t);
    CHECK(std::abs(c[0] - 2) <= 1e-12);
    CHECK(std::abs(c[2]) <= 1e-12);
    CHECK(norm(sub(c, point(wall, rp.rails[1].base, t))) <= 1e-12);
    CHECK(std::abs(a[0] - (2 + d1)) <= 1e-12);
    CHECK(std::abs(a[1] - c[1]) <= 1e-12);
    CHECK(std::abs(a[2]) <= 1e-12);
    CHECK(std::abs(b[0] - 2) <= 1e-12);
    CHECK(std::abs(b[1] - c[1]) <= 1e-12);
    CHECK(std::abs(b[2] - d2) <= 1e-12);
  }
  // C runs over the whole floor, y from 0 to 4.
  const double y0 = point(floor, rp.rails[0].base, 0.0)[1], y1 = point(floor, rp.rails[0].base, 1.0)[1];
  CHECK(std::min(y0, y1) == Approx(0.0).margin(1e-12));
  CHECK(std::max(y0, y1) == Approx(4.0).margin(1e-12));

  SECTION("flip puts each rail on the other side") {
    fillet::RailOptions o;
    o.flip = {true, true};
    const auto f = fillet::offset_rails(floor, wall, {1, 1}, curves[0], d, o);
    for (int k = 0; k <= 50; ++k) {
      const double t = k / 50.0;
      CHECK(std::abs(point(floor, f.rails[0].rail, t)[0] - (2 - d1)) <= 1e-12);
      CHECK(std::abs(point(wall, f.rails[1].rail, t)[2] + d2) <= 1e-12);
    }
    // So do the outward signs: the wall cell at x > 2 puts the floor rail at x < 2.
    const auto g = fillet::offset_rails(floor, wall, {1, -1}, curves[0], d);
    CHECK(std::abs(point(floor, g.rails[0].rail, 0.5)[0] - (2 - d1)) <= 1e-12);
    CHECK(std::abs(point(wall, g.rails[1].rail, 0.5)[2] - d2) <= 1e-12);
  }

  SECTION("distances the faces cannot hold, and bad distances") {
    const auto fails = [&](std::array<double, 2> dd, const std::string& face) {
      try {
        (void)fillet::offset_rails(floor, wall, {1, 1}, curves[0], dd);
        FAIL("no error for distances " << dd[0] << ", " << dd[1]);
      } catch (const Error& e) {
        CHECK(e.kind() == ErrorKind::bad_input);
        const std::string m = e.what();
        INFO(m);
        CHECK(m.find(face) != std::string::npos);
        if (dd[0] > 0 && dd[1] > 0) {
          CHECK(m.find("leaves the face at t = ") != std::string::npos);
          CHECK(m.find("(u, v) = ") != std::string::npos);
        }
      }
    };
    fails({2.5, 0.5}, "face 1");  // x = 4.5 is off the floor (x <= 4)
    fails({0.5, 4.5}, "face 2");  // z = 4.5 is above the wall (z <= 4)
    fails({0.0, 0.5}, "face 1");
    fails({0.5, -1.0}, "face 2");
    // The boundary itself is still on the face: x = 4.
    const auto edge = fillet::offset_rails(floor, wall, {1, 1}, curves[0], {2.0, 0.5});
    CHECK(std::abs(point(floor, edge.rails[0].rail, 0.3)[0] - 4.0) <= 1e-12);
  }
}

TEST_CASE("a cylinder on a floor: circles of radius r + d1 and height d2", "[rails]") {
  const double r = 1.0, d1 = 0.4, d2 = 0.3;
  const Surface floor = plane_patch({-3, -3, 0}, {6, 0, 0}, {0, 6, 0});
  const Surface cyl = cylinder(r, -1, 2);
  const auto curves = geom::intersect_surfaces(floor, cyl);
  REQUIRE(curves.size() == 1);
  const std::array<double, 2> outward{1.0, outward_from(cyl, {0, 0, 0.5})};
  const std::array<double, 2> d{d1, d2};
  const fillet::RailPair rp = fillet::offset_rails(floor, cyl, outward, curves[0], d);
  const double tol = 1e-7;
  check_generic(floor, cyl, rp, d, tol);
  for (int k = 0; k <= 500; ++k) {
    const double t = k / 500.0;
    const P3 a = point(floor, rp.rails[0].rail, t), b = point(cyl, rp.rails[1].rail, t);
    CHECK(std::hypot(a[0], a[1]) == Approx(r + d1).margin(tol));
    CHECK(std::abs(a[2]) <= 1e-12);
    CHECK(std::hypot(b[0], b[1]) == Approx(r).margin(tol));
    CHECK(b[2] == Approx(d2).margin(tol));
  }
  fillet::RailOptions o;
  o.flip = {true, false};
  const auto in = fillet::offset_rails(floor, cyl, outward, curves[0], d, o);
  check_generic(floor, cyl, in, d, tol, 300);
  for (int k = 0; k <= 200; ++k) {
    const P3 a = point(floor, in.rails[0].rail, k / 200.0);
    CHECK(std::hypot(a[0], a[1]) == Approx(r - d1).margin(tol));
  }
  // More than the floor holds (it ends at |x| = 3).
  CHECK_THROWS_AS(fillet::offset_rails(floor, cyl, outward, curves[0], {2.5, d2}), Error);
}

TEST_CASE("a plane through a sphere: a closed loop and its rails", "[rails]") {
  const Surface sphere = unit_sphere();
  const Surface plane = plane_patch({-2, 0.5, -2}, {4, 0, 0}, {0, 0, 4});  // y = 1/2
  const auto curves = geom::intersect_surfaces(plane, sphere);
  REQUIRE(curves.size() == 1);
  REQUIRE(curves[0].closed);
  // The plane's cell is y > 1/2, the sphere's the ball.
  const std::array<double, 2> outward{outward_from(plane, {0, 1, 0}), outward_from(sphere, {0, 0, 0})};
  const double d1 = 0.25, d2 = 0.3, tol = 1e-7;
  const std::array<double, 2> d{d1, d2};
  const fillet::RailPair rp = fillet::offset_rails(plane, sphere, outward, curves[0], d);
  CHECK(rp.closed);
  check_generic(plane, sphere, rp, d, tol);
  const double rho = std::sqrt(0.75);
  const double y_rail = std::sin(M_PI / 6 - 2 * std::asin(d2 / 2));  // below the plane: outside its cell
  for (int k = 0; k <= 500; ++k) {
    const double t = k / 500.0;
    const P3 a = point(plane, rp.rails[0].rail, t), b = point(sphere, rp.rails[1].rail, t);
    CHECK(std::hypot(a[0], a[2]) == Approx(rho + d1).margin(tol));
    CHECK(a[1] == Approx(0.5).margin(1e-12));
    CHECK(b[1] == Approx(y_rail).margin(tol));
    CHECK(norm(b) == Approx(1.0).margin(3e-9));  // the sphere is within 2e-9 of the unit sphere
  }
  // Closed: both rails and both bases start where they end.
  for (const auto& r : rp.rails) {
    const auto b0 = r.base.eval({0.0}), b1 = r.base.eval({1.0});
    const auto r0 = r.rail.eval({0.0}), r1 = r.rail.eval({1.0});
    CHECK(std::hypot(b0[0] - b1[0], b0[1] - b1[1]) == 0.0);
    CHECK(std::hypot(r0[0] - r1[0], r0[1] - r1[1]) == 0.0);
  }
  fillet::RailOptions o;
  o.flip = {false, true};
  const auto up = fillet::offset_rails(plane, sphere, outward, curves[0], d, o);
  for (int k = 0; k <= 100; ++k)
    CHECK(point(sphere, up.rails[1].rail, k / 100.0)[1] ==
          Approx(std::sin(M_PI / 6 + 2 * std::asin(d2 / 2))).margin(tol));
  // A chord longer than the sphere's diameter is not on the sphere.
  try {
    (void)fillet::offset_rails(plane, sphere, outward, curves[0], {d1, 2.5});
    FAIL("no error");
  } catch (const Error& e) {
    CHECK(e.kind() == ErrorKind::bad_input);
    CHECK(std::string(e.what()).find("face 2") != std::string::npos);
  }
}

TEST_CASE("a tilted plane through a cylinder: rails of an ellipse", "[rails]") {
  const double tilt = std::tan(M_PI / 6);
  const Surface plane = plane_patch({-3, -3, -3 * tilt}, {6, 0, 0}, {0, 6, 6 * tilt});  // z = y tan 30
  const Surface cyl = cylinder(1.0, -2, 2);
  const auto curves = geom::intersect_surfaces(plane, cyl);
  REQUIRE(curves.size() == 1);
  const std::array<double, 2> outward{outward_from(plane, {0, 0, -1}), outward_from(cyl, {0, 0, 0})};
  const std::array<double, 2> d{0.6, 0.45};
  for (const bool flip : {false, true}) {
    fillet::RailOptions o;
    o.flip = {flip, flip};
    const auto rp = fillet::offset_rails(plane, cyl, outward, curves[0], d, o);
    CHECK(check_generic(plane, cyl, rp, d, o.tolerance) <= o.tolerance);
    // Sides: outside the cylinder on the plane (inside flipped), above the plane on the cylinder.
    for (int k = 0; k <= 100; ++k) {
      const double t = k / 100.0;
      const P3 a = point(plane, rp.rails[0].rail, t), b = point(cyl, rp.rails[1].rail, t);
      CHECK((std::hypot(a[0], a[1]) > 1.0) == !flip);
      CHECK((b[2] > b[1] * tilt) == !flip);
    }
  }
}

TEST_CASE("an offset beyond the radius of curvature is trimmed at its self-crossing", "[rails]") {
  // The wall is the parabola y = x^2, x in [-1, 1] (quadratic in u, exact), extruded over
  // z in [-1, 1]. Its cell lies on the convex side (outward -1: S_u x S_v points to -y at the
  // apex), so the floor rail goes into the concave side.
  const Surface floor = plane_patch({-2, -1, 0}, {4, 0, 0}, {0, 4, 0});
  const Surface wall({KnotVector::bezier(3), KnotVector::bezier(2)}, 3,
                     std::vector<double>{-1, 1, -1, 0, -1, -1, 1, 1, -1, -1, 1, 1, 0, -1, 1, 1, 1, 1});
  const auto curves = geom::intersect_surfaces(floor, wall);
  REQUIRE(curves.size() == 1);
  const double d1 = 0.8, d2 = 0.5, tol = 1e-7;
  const std::array<double, 2> d{d1, d2};
  const fillet::RailPair rp = fillet::offset_rails(floor, wall, {1, -1}, curves[0], d);
  check_generic(floor, wall, rp, d, tol);
  REQUIRE(rp.rails[0].trimmed.size() == 1);
  CHECK(rp.rails[1].trimmed.empty());
  const double t0 = rp.rails[0].trimmed[0][0], t1 = rp.rails[0].trimmed[0][1];
  const double xs = std::sqrt(4 * d1 * d1 - 1) / 2, ys = (4 * d1 * d1 - 1) / 4 + 0.5;
  // The crossing parameters: C at x = -xs and +xs (in either order).
  const P3 c0 = point(floor, rp.rails[0].base, t0), c1 = point(floor, rp.rails[0].base, t1);
  CHECK(std::abs(c0[0]) == Approx(xs).margin(1e-6));
  CHECK(std::abs(c1[0]) == Approx(xs).margin(1e-6));
  CHECK(c0[0] * c1[0] < 0);
  // Constant at the crossing over [t0, t1], which is at distance d from C at both ends.
  for (int k = 0; k <= 100; ++k) {
    const P3 a = point(floor, rp.rails[0].rail, t0 + (t1 - t0) * k / 100.0);
    CHECK(std::abs(a[0]) <= 1e-6);
    CHECK(a[1] == Approx(ys).margin(1e-6));
  }
  const P3 x = point(floor, rp.rails[0].rail, t0);
  CHECK(norm(sub(x, c0)) == Approx(d1).margin(tol));
  CHECK(norm(sub(x, c1)) == Approx(d1).margin(tol));
  // C is the parabola; the wall rail is C lifted by d2.
  for (int k = 0; k <= 200; ++k) {
    const double t = k / 200.0;
    const P3 c = point(floor, rp.rails[0].base, t);
    CHECK(c[1] == Approx(c[0] * c[0]).margin(tol));
    const P3 b = point(wall, rp.rails[1].rail, t);
    CHECK(norm(sub(b, {c[0], c[1], d2})) <= tol);
  }
  // What is left of the rail does not cross itself: the parts before and after the trimmed
  // stretch only touch at the crossing, their shared end.
  const std::array<Curve, 2> parts{spline::restrict_to(rp.rails[0].rail, 0, 0.0, t0),
                                   spline::restrict_to(rp.rails[0].rail, 0, t1, 1.0)};
  CHECK_FALSE(geom::first_crossing(parts, 1e-9).has_value());
  // Below the radius of curvature nothing is trimmed.
  const auto small = fillet::offset_rails(floor, wall, {1, -1}, curves[0], {0.45, d2});
  CHECK(small.rails[0].trimmed.empty());
  check_generic(floor, wall, small, {0.45, d2}, tol, 300);
}

TEST_CASE("an ellipse offset inwards beyond its smallest radius: two trimmed swallowtails", "[rails]") {
  // The elliptic cylinder x^2/4 + y^2 = 1 (radius of curvature b^2/a = 1/2 at (+-2, 0)), seam at
  // (0, 1), on a floor; the floor rail flipped into the ellipse at d = 0.7. By symmetry both
  // crossings lie on y = 0: from C at (2c, +-s) with c^2 = (4 - 4 d^2) / 3, at x = +-1.5 c.
  Surface wall = cylinder(1.0, -1, 1);
  for (int i = 0; i < wall.size(); ++i) wall.point(i)[0] *= 2;
  const Surface floor = plane_patch({-3, -2, 0}, {6, 0, 0}, {0, 4, 0});
  const auto curves = geom::intersect_surfaces(floor, wall);
  REQUIRE(curves.size() == 1);
  const std::array<double, 2> outward{1.0, outward_from(wall, {0, 0, 0})};
  const double d1 = 0.7, d2 = 0.2, tol = 1e-7;
  const std::array<double, 2> d{d1, d2};
  fillet::RailOptions o;
  o.flip = {true, false};
  const fillet::RailPair rp = fillet::offset_rails(floor, wall, outward, curves[0], d, o);
  check_generic(floor, wall, rp, d, tol);
  REQUIRE(rp.rails[0].trimmed.size() == 2);
  CHECK(rp.rails[1].trimmed.empty());
  const double c = std::sqrt((4 - 4 * d1 * d1) / 3), s = std::sqrt(1 - c * c);
  double sides = 0.0;
  for (const auto& m : rp.rails[0].trimmed) {
    const P3 x = point(floor, rp.rails[0].rail, 0.5 * (m[0] + m[1]));
    CHECK(std::abs(x[0]) == Approx(1.5 * c).margin(1e-6));
    CHECK(x[1] == Approx(0.0).margin(1e-6));
    sides += x[0];
    for (const double t : {m[0], m[1]}) {
      const P3 e = point(floor, rp.rails[0].base, t);
      CHECK(std::abs(e[0]) == Approx(2 * c).margin(1e-6));
      CHECK(std::abs(e[1]) == Approx(s).margin(1e-6));
      CHECK(norm(sub(point(floor, rp.rails[0].rail, t), x)) <= 1e-12);
    }
  }
  CHECK(std::abs(sides) <= 1e-5);  // one at each end of the major axis
}

TEST_CASE("faces tangent along C: the side cannot be decided", "[rails]") {
  // z = 0 and z = (x - 2)^2 touch along x = 2, z = 0 (intersect_surfaces does not report
  // tangential contacts, so the curve is given by hand).
  const Surface floor = plane_patch({0, 0, 0}, {4, 0, 0}, {0, 4, 0});
  const Surface trough({KnotVector::bezier(3), KnotVector::bezier(2)}, 3,
                       std::vector<double>{1, 0, 1, 2, 0, -1, 3, 0, 1, 1, 4, 1, 2, 4, -1, 3, 4, 1});
  geom::IntersectionCurve c;
  for (int k = 0; k <= 10; ++k) {
    const double y = 0.4 * k;
    c.points.push_back({{2, y, 0}, {0.5, y / 4}, {0.5, y / 4}});
  }
  try {
    (void)fillet::offset_rails(floor, trough, {1, 1}, c, {0.5, 0.5});
    FAIL("no error");
  } catch (const Error& e) {
    CHECK(e.kind() == ErrorKind::failed);
    CHECK(std::string(e.what()).find("tangent") != std::string::npos);
  }
  geom::IntersectionCurve one;
  one.points.push_back(c.points[0]);
  CHECK_THROWS_AS(fillet::offset_rails(floor, trough, {1, 1}, one, {0.5, 0.5}), Error);
}
