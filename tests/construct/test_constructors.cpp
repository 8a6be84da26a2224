// Constructors (construct/constructors.hpp). Truths: each constructor's closed formula evaluated
// independently from its inputs at random parameters (ruling, extrusion, Coons patch and volume,
// half Boolean sums of Fadila et al. 2023, Sec. 3); the boundary interpolation of Fadila et al.
// 2023 Lemmas 1-3; a sweep reproduces a trivariate that is cubic in w from four of its sections;
// revolution follows the exact rotation within the stated tolerance and gives the analytic volume
// of a solid of revolution (Pappus).
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "trivox/construct/constructors.hpp"
#include "trivox/error.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/refine.hpp"

using namespace trivox;
using namespace trivox::construct;
using spline::KnotVector;

namespace {

constexpr double pi = 3.14159265358979323846;

std::mt19937& rng() {
  static std::mt19937 g(20261201);
  return g;
}
double uniform(double a = 0.0, double b = 1.0) { return std::uniform_real_distribution<double>(a, b)(rng()); }

/// A random curve in R^dim of the given order and control-point count on [a, b] with uniform
/// interior knots (clamped).
Curve random_curve(int order, int count, int dim, double a = 0.0, double b = 1.0) {
  std::vector<double> pts;
  for (int i = 0; i < count * dim; ++i) pts.push_back(uniform(-2, 2));
  return Curve({KnotVector::uniform(order, count - order + 1, a, b)}, dim, pts);
}

/// A cubic-in-everything trivariate in R^4: a smooth map plus a property.
Trivariate smooth_trivariate() {
  std::vector<double> pts;
  const int n = 5;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double u = i / 4.0, v = j / 4.0, w = k / 4.0;
        pts.insert(pts.end(), {u + 0.2 * std::sin(3 * v + w), v + 0.1 * u * w, w + 0.15 * std::cos(2 * u * v), u * v + w});
      }
  const KnotVector kv = KnotVector::uniform(4, 2);
  return Trivariate({kv, kv, kv}, 4, pts);
}

template <int P>
double max_diff(const spline::TensorSpline<P>& a, const spline::TensorSpline<P>& b) {
  double worst = 0.0;
  for (int n = 0; n < 300; ++n) {
    std::array<double, P> t;
    for (auto& x : t) x = uniform();
    const auto p = a.eval(t), q = b.eval(t);
    for (std::size_t c = 0; c < p.size(); ++c) worst = std::max(worst, std::abs(p[c] - q[c]));
  }
  return worst;
}

std::vector<double> at(const Curve& c, double t) {
  const auto d = c.domain(0);
  return c.eval({d[0] + t * (d[1] - d[0])});
}

void check_close(const std::vector<double>& a, const std::vector<double>& b, double tol) {
  REQUIRE(a.size() == b.size());
  for (std::size_t c = 0; c < a.size(); ++c) CHECK(std::abs(a[c] - b[c]) <= tol);
}

template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    CHECK(e.kind() == ErrorKind::bad_input);
    return e.what();
  }
  FAIL("expected a trivox::Error");
  return {};
}

}  // namespace

TEST_CASE("normalized and common_space keep the functions and share one space", "[construct]") {
  const Curve a = random_curve(3, 6, 4, 2.0, 5.0);
  const Curve b = spline::elevate(random_curve(4, 5, 4, -1.0, 1.0), 0, 1);
  const Curve in[2] = {a, b};
  const auto cs = common_space<1>(in);
  REQUIRE(cs.size() == 2);
  CHECK(cs[0].knots(0) == cs[1].knots(0));
  CHECK(cs[0].domain(0) == std::array<double, 2>{0.0, 1.0});
  for (int i = 0; i <= 20; ++i) {
    const double t = i / 20.0;
    check_close(cs[0].eval({t}), at(a, t), 1e-12);
    check_close(cs[1].eval({t}), at(b, t), 1e-12);
  }
}

TEST_CASE("ruled and extruded surfaces and volumes follow their formulas", "[construct]") {
  const Curve b = random_curve(3, 5, 3), t = random_curve(4, 6, 3, 1.0, 3.0);
  const Surface s = ruled(b, t);
  const Surface s3 = ruled(b, t, 3);
  CHECK(s.orders()[1] == 2);
  CHECK(s3.orders()[1] == 3);
  for (int n = 0; n < 200; ++n) {
    const double u = uniform(), v = uniform();
    const auto pb = at(b, u), pt = at(t, u);
    std::vector<double> expect(3);
    for (int c = 0; c < 3; ++c) expect[c] = (1 - v) * pb[c] + v * pt[c];
    check_close(s.eval({u, v}), expect, 1e-12);
    check_close(s3.eval({u, v}), expect, 1e-12);
  }
  // A unit square extruded by (0, 0, 2) (with a property riding along): volume 2.
  std::vector<double> sq;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) sq.insert(sq.end(), {double(i), double(j), 0.0, 0.5});
  const Surface square({KnotVector::bezier(2), KnotVector::bezier(2)}, 4, sq);
  const double h[3] = {0.0, 0.0, 2.0};
  const Trivariate box = extrude(square, h);
  CHECK(geom::volume(box) == Approx(2.0).epsilon(1e-14));
  check_close(box.eval({0.3, 0.6, 0.25}), {0.3, 0.6, 0.5, 0.5}, 1e-14);
  const double bad[5] = {1, 2, 3, 4, 5};
  CHECK_THAT(error_of([&] { extrude(square, bad); }), Catch::Contains("expected 1..4"));
}

TEST_CASE("circle arcs and revolutions are within the stated tolerance of the rotation", "[construct]") {
  for (double angle : {pi / 3, pi / 2, pi, 2 * pi}) {
    for (double tol : {1e-3, 1e-6, 1e-9}) {
      const Curve arc = circle_arc(angle, tol);
      double err = 0.0;
      for (int i = 0; i <= 2000; ++i) {
        const double t = i / 2000.0;
        const auto p = arc.eval({t});
        err = std::max(err, std::hypot(p[0] - std::cos(t * angle), p[1] - std::sin(t * angle)));
      }
      CHECK(err <= tol);
    }
  }
  const Curve full = circle_arc(2 * pi, 1e-6);
  CHECK(full.point(0)[0] == 1.0);
  CHECK(full.point(full.size() - 1)[0] == 1.0);
  CHECK(full.point(full.size() - 1)[1] == 0.0);

  // A rectangle [1, 2] x [0, 1] in the xz-plane (with a property) revolved about z: the annulus
  // solid, volume pi (2^2 - 1^2) * 1 = 3 pi; every point keeps its distance to the axis and
  // its height; the property is unchanged.
  std::vector<double> rect;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) rect.insert(rect.end(), {1.0 + i, 0.0, double(j), 7.0 + i});
  const Surface profile({KnotVector::bezier(2), KnotVector::bezier(2)}, 4, rect);
  Revolution r;
  r.relative_tolerance = 1e-7;
  const Trivariate ring = revolve(profile, r);
  CHECK(std::abs(geom::volume(ring) - 3 * pi) <= 1e-6 * 3 * pi);
  for (int n = 0; n < 300; ++n) {
    const double u = uniform(), v = uniform(), w = uniform();
    const auto p = ring.eval({u, v, w});
    const double radius = 1.0 + u;
    CHECK(std::abs(std::hypot(p[0], p[1]) - radius) <= 1e-7 * 2.0);
    CHECK(std::abs(std::atan2(p[1], p[0]) - std::remainder(2 * pi * w, 2 * pi)) <= 1e-6);
    CHECK(p[2] == Approx(v).margin(1e-14));
    CHECK(p[3] == Approx(7.0 + u).margin(1e-13));
  }
  // A half turn about a tilted axis through another origin: Pappus, V = angle * area * centroid
  // distance. The square [1,2]x[0,1] in the plane containing the axis (0,0,1) through (0,0,0) is
  // generic enough; here the axis is x through (0, -3, 0) and the square lies in the xy-plane at
  // y in [0, 1] (distances 3..4 from the axis): V = pi * 1 * 3.5.
  std::vector<double> sq2;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) sq2.insert(sq2.end(), {double(i), double(j), 0.0});
  const Surface square({KnotVector::bezier(2), KnotVector::bezier(2)}, 3, sq2);
  Revolution half;
  half.origin = {0, -3, 0};
  half.axis = {2, 0, 0};
  half.angle = pi;
  const Trivariate shell = revolve(square, half);
  CHECK(std::abs(std::abs(geom::signed_volume(shell)) - pi * 3.5) <= 1e-6 * pi * 3.5);

  Revolution zero;
  zero.axis = {0, 0, 0};
  CHECK_THAT(error_of([&] { revolve(profile, zero); }), Catch::Contains("axis has zero length"));
  Revolution too_far;
  too_far.angle = 7.0;
  CHECK_THAT(error_of([&] { revolve(profile, too_far); }), Catch::Contains("expected a value in (0, 2 pi]"));
}

TEST_CASE("Boolean sum surface is the Coons patch of its four boundaries", "[construct]") {
  // Four boundaries of a random surface, each in its own function space and domain.
  const Surface base({KnotVector::uniform(4, 2), KnotVector::uniform(3, 3)}, 4, [] {
    std::vector<double> p;
    for (int i = 0; i < 5 * 5 * 4; ++i) p.push_back(uniform(-1, 1));
    return p;
  }());
  const Curve bottom = spline::iso(base, 1, 0.0), top = spline::reparametrize(spline::iso(base, 1, 1.0), 0, 3.0, 4.0);
  const Curve left = spline::elevate(spline::iso(base, 0, 0.0), 0, 2), right = spline::iso(base, 0, 1.0);
  const Surface S = boolean_sum(bottom, top, left, right);
  for (int n = 0; n < 300; ++n) {
    const double u = uniform(), v = uniform();
    const auto b = at(bottom, u), t = at(top, u), l = at(left, v), r = at(right, v);
    const auto c00 = at(bottom, 0), c10 = at(bottom, 1), c01 = at(top, 0), c11 = at(top, 1);
    std::vector<double> expect(4);
    for (int c = 0; c < 4; ++c)
      expect[c] = (1 - v) * b[c] + v * t[c] + (1 - u) * l[c] + u * r[c] -
                  ((1 - u) * (1 - v) * c00[c] + u * (1 - v) * c10[c] + (1 - u) * v * c01[c] + u * v * c11[c]);
    check_close(S.eval({u, v}), expect, 1e-11);
    // Interpolation of the four boundaries.
    check_close(S.eval({u, 0.0}), b, 1e-12);
    check_close(S.eval({u, 1.0}), t, 1e-12);
    check_close(S.eval({0.0, v}), l, 1e-12);
    check_close(S.eval({1.0, v}), r, 1e-12);
  }
  // A ruled surface is reproduced (the Coons projector keeps what is linear in one direction).
  const Surface ruled_s = ruled(random_curve(3, 4, 3), random_curve(3, 4, 3));
  const Surface again = boolean_sum(spline::iso(ruled_s, 1, 0.0), spline::iso(ruled_s, 1, 1.0),
                                    spline::iso(ruled_s, 0, 0.0), spline::iso(ruled_s, 0, 1.0));
  CHECK(max_diff(again, ruled_s) <= 1e-12);
  // Corners that do not meet are named with the gap.
  Curve moved = right;
  moved.point(0)[0] += 0.25;
  const auto msg = error_of([&] { boolean_sum(bottom, top, left, moved); });
  CHECK_THAT(msg, Catch::Contains("bottom(1) and right(0) are 0.25 apart"));
}

TEST_CASE("volumetric Boolean sum interpolates its six faces and is the trilinear Coons volume", "[construct]") {
  const Trivariate T0 = smooth_trivariate();
  std::vector<Surface> faces;
  for (auto f : spline::all_faces) faces.push_back(spline::boundary_face(T0, f));
  faces[1] = spline::elevate(faces[1], 0, 1);           // another function space
  faces[4] = spline::refine_uniform(faces[4], 1, 2);    // and another
  const Trivariate T = boolean_sum(faces);
  for (int n = 0; n < 200; ++n) {
    const double u = uniform(), v = uniform(), w = uniform();
    // Faces interpolated (Massarwi & Elber 2016, Sec. 3.2.2 item 4).
    check_close(T.eval({0.0, v, w}), T0.eval({0.0, v, w}), 1e-11);
    check_close(T.eval({1.0, v, w}), T0.eval({1.0, v, w}), 1e-11);
    check_close(T.eval({u, 0.0, w}), T0.eval({u, 0.0, w}), 1e-11);
    check_close(T.eval({u, 1.0, w}), T0.eval({u, 1.0, w}), 1e-11);
    check_close(T.eval({u, v, 0.0}), T0.eval({u, v, 0.0}), 1e-11);
    check_close(T.eval({u, v, 1.0}), T0.eval({u, v, 1.0}), 1e-11);
    // The trilinear Coons formula from T0's boundary values.
    const double U[2] = {1 - u, u}, V[2] = {1 - v, v}, W[2] = {1 - w, w};
    std::vector<double> e(4, 0.0);
    const auto add = [&](const std::vector<double>& p, double f) {
      for (int c = 0; c < 4; ++c) e[c] += f * p[c];
    };
    for (int a = 0; a < 2; ++a) {
      add(T0.eval({double(a), v, w}), U[a]);
      add(T0.eval({u, double(a), w}), V[a]);
      add(T0.eval({u, v, double(a)}), W[a]);
      for (int b = 0; b < 2; ++b) {
        add(T0.eval({double(a), double(b), w}), -U[a] * V[b]);
        add(T0.eval({double(a), v, double(b)}), -U[a] * W[b]);
        add(T0.eval({u, double(a), double(b)}), -V[a] * W[b]);
        for (int c = 0; c < 2; ++c) add(T0.eval({double(a), double(b), double(c)}), U[a] * V[b] * W[c]);
      }
    }
    check_close(T.eval({u, v, w}), e, 1e-11);
  }
  // A face out of place is named.
  auto shifted = faces;
  for (int i = 0; i < shifted[3].size(); ++i) shifted[3].point(i)[2] += 0.5;
  const auto msg = error_of([&] { boolean_sum(shifted); });
  CHECK_THAT(msg, Catch::Contains("face v1") && Catch::Contains("differ by 0.5"));
  CHECK_THAT(error_of([&] { boolean_sum(std::span<const Surface>(faces.data(), 5)); }),
             Catch::Contains("expected six"));
}

TEST_CASE("half Boolean sums satisfy Fadila et al. 2023 Lemmas 1-3 and their formulas", "[construct]") {
  // Lemma 1: two curves sharing their start.
  Curve c1 = random_curve(3, 5, 3), c2 = random_curve(4, 4, 3, -2.0, 0.0);
  for (int c = 0; c < 3; ++c) c2.point(0)[c] = c1.point(0)[c];
  const Surface S = half_boolean_sum(c1, c2);
  const auto P = at(c1, 0.0);
  for (int n = 0; n < 200; ++n) {
    const double u = uniform(), v = uniform();
    check_close(S.eval({u, 0.0}), at(c1, u), 1e-12);
    check_close(S.eval({0.0, v}), at(c2, v), 1e-12);
    const auto a = at(c1, u), b = at(c2, v);
    check_close(S.eval({u, v}), {a[0] + b[0] - P[0], a[1] + b[1] - P[1], a[2] + b[2] - P[2]}, 1e-12);
  }
  Curve apart = c2;
  apart.point(0)[1] += 1.0;
  CHECK_THAT(error_of([&] { half_boolean_sum(c1, apart); }), Catch::Contains("1 apart"));

  // Lemmas 2 and 3 on faces of a trivariate around its corner (0, 0, 0).
  const Trivariate T0 = smooth_trivariate();
  const Surface s1 = spline::boundary_face(T0, spline::Face::w0);  // (u, v)
  const Surface s2u = spline::boundary_face(T0, spline::Face::v0); // (u, w)
  const Trivariate T2 = half_boolean_sum(s1, s2u);
  for (int n = 0; n < 200; ++n) {
    const double u = uniform(), v = uniform(), w = uniform();
    check_close(T2.eval({u, v, 0.0}), s1.eval({u, v}), 1e-12);
    check_close(T2.eval({u, 0.0, w}), s2u.eval({u, w}), 1e-12);
    const auto a = s1.eval({u, v}), b = s2u.eval({u, w}), c = s1.eval({u, 0.0});
    std::vector<double> e(4);
    for (int k = 0; k < 4; ++k) e[k] = a[k] + b[k] - c[k];
    check_close(T2.eval({u, v, w}), e, 1e-12);
  }
  const Surface s2 = spline::boundary_face(T0, spline::Face::u0);  // (v, w)
  const Surface s3 = spline::boundary_face(T0, spline::Face::v0);  // (u, w)
  const Trivariate T3 = half_boolean_sum(s1, s2, s3);
  for (int n = 0; n < 200; ++n) {
    const double u = uniform(), v = uniform(), w = uniform();
    check_close(T3.eval({u, v, 0.0}), s1.eval({u, v}), 1e-12);
    check_close(T3.eval({0.0, v, w}), s2.eval({v, w}), 1e-12);
    check_close(T3.eval({u, 0.0, w}), s3.eval({u, w}), 1e-12);
    const auto a = s1.eval({u, v}), b = s2.eval({v, w}), c = s3.eval({u, w});
    const auto C1 = T0.eval({u, 0, 0}), C2 = T0.eval({0, v, 0}), C3 = T0.eval({0, 0, w}), p = T0.eval({0, 0, 0});
    std::vector<double> e(4);
    for (int k = 0; k < 4; ++k) e[k] = a[k] + b[k] + c[k] - (C1[k] + C2[k] + C3[k]) + p[k];
    check_close(T3.eval({u, v, w}), e, 1e-12);
  }
  CHECK_THAT(error_of([&] { half_boolean_sum(s1, s3, s2); }), Catch::Contains("surface 0 at v = 0 and surface 2 at w = 0 differ"));
}

TEST_CASE("a sweep through four sections reproduces a trivariate cubic in w", "[construct]") {
  const Trivariate T0 = smooth_trivariate();  // cubic B-spline in w with one interior knot
  // A single cubic Bezier piece in w is in the span of the sweep's interpolation space.
  const Trivariate T1 = spline::restrict_to(T0, 2, 0.0, 0.5);
  const Trivariate T = spline::reparametrize(T1, 2, 0.0, 1.0);
  const double w[4] = {0.0, 0.2, 0.7, 1.0};
  std::vector<Surface> sections;
  for (double t : w) sections.push_back(spline::iso(T, 2, t));
  const Trivariate S = sweep(sections, w);
  CHECK(max_diff(S, T) <= 1e-11);
  // Chord-length parameters place the sections where they are; every section is interpolated.
  const Trivariate S2 = sweep(sections);
  const auto t2 = sweep_params<3>(sections);
  REQUIRE(t2.size() == 4);
  CHECK(t2.front() == 0.0);
  CHECK(t2.back() == 1.0);
  for (std::size_t i = 0; i < 4; ++i)
    for (int n = 0; n < 30; ++n) {
      const double u = uniform(), v = uniform();
      check_close(S2.eval({u, v, t2[i]}), sections[i].eval({u, v}), 1e-11);
    }
  const double bad[4] = {0.0, 0.5, 0.5, 1.0};
  CHECK_THAT(error_of([&] { sweep(sections, bad); }), Catch::Contains("strictly increasing"));
  CHECK_THAT(error_of([&] { sweep(std::span<const Surface>(sections.data(), 1)); }), Catch::Contains("at least 2"));
}
