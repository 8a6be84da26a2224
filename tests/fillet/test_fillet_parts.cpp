// The fillet's building blocks: composition (Masalha et al. 2021, Sec. 1.5), blending surfaces
// (Alg. 1 and the flend section, Eager & Dannenhoffer 2019, Sec. II.A), the ruled-volume fillet
// with parametric property blending (Alg. 2, Sec. 7.1). Expected values are exact: pointwise
// composition, the chamfer plane, tangent planes of planes, Green's-theorem
// areas of the Hermite section.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "corner.hpp"
#include "trivox/construct/constructors.hpp"
#include "trivox/fillet/blend_surface.hpp"
#include "trivox/fillet/compose.hpp"
#include "trivox/fillet/ruled_fillet.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/refine.hpp"

using namespace trivox;
using spline::Curve;
using spline::KnotVector;
using spline::Surface;
using Vec = std::array<double, 3>;
using fillet_test::Corner;

namespace {

Surface random_bicubic(std::mt19937& rng, int dim, const KnotVector& ku, const KnotVector& kv) {
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  std::vector<double> pts(static_cast<std::size_t>(ku.size() * kv.size() * dim));
  for (double& p : pts) p = d(rng);
  return Surface({ku, kv}, dim, pts);
}

/// A cubic curve in [0.1, 0.9]^2 through random points (3 spans).
Curve random_param_curve(std::mt19937& rng, double lo, double hi) {
  std::uniform_real_distribution<double> d(lo, hi);
  std::vector<double> pts(12);
  for (double& p : pts) p = d(rng);
  return Curve({KnotVector(4, {0, 0, 0, 0, 1.0 / 3, 2.0 / 3, 1, 1, 1, 1})}, 2, pts);
}

Vec at(const Surface& s, double u, double v) {
  const auto p = s.eval({u, v});
  return {p[0], p[1], p[2]};
}

double angle_between_normals(const Surface& a, double ua, double va, const Vec& n) {
  const auto d = a.eval_derivatives({ua, va}, 1);
  const std::size_t k = static_cast<std::size_t>(a.dim());
  const Vec su{d[k], d[k + 1], d[k + 2]}, sv{d[2 * k], d[2 * k + 1], d[2 * k + 2]};
  const Vec m{su[1] * sv[2] - su[2] * sv[1], su[2] * sv[0] - su[0] * sv[2], su[0] * sv[1] - su[1] * sv[0]};
  const double c = std::abs(m[0] * n[0] + m[1] * n[1] + m[2] * n[2]) / std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
  return std::acos(std::min(1.0, c));
}

}  // namespace

TEST_CASE("composition of a surface with a curve and with a surface is exact", "[fillet][compose]") {
  std::mt19937 rng(7);
  const KnotVector bez = KnotVector::bezier(4);
  const Surface s = random_bicubic(rng, 4, bez, bez);
  const Curve c = random_param_curve(rng, 0.1, 0.9);
  const Curve sc = fillet::compose(s, c);
  CHECK(sc.orders()[0] == 19);  // degree (3 + 3) * 3
  CHECK(sc.knots(0).multiplicity(1.0 / 3) == 16);  // C2 kept: 18 - 2
  std::uniform_real_distribution<double> t01(0.0, 1.0);
  double worst = 0.0;
  for (int i = 0; i < 500; ++i) {
    const double t = t01(rng);
    const auto uv = c.eval({t});
    const auto e = s.eval({uv[0], uv[1]});
    const auto g = sc.eval({t});
    for (int j = 0; j < 4; ++j) worst = std::max(worst, std::abs(e[static_cast<std::size_t>(j)] - g[static_cast<std::size_t>(j)]));
  }
  CHECK(worst < 1e-11);

  const Curve c2 = random_param_curve(rng, 0.1, 0.9);
  const Surface r = fillet::subregion(s, c, c2, {fillet::SubregionMethod::compose});
  CHECK(r.orders()[0] == 19);
  CHECK(r.orders()[1] == 7);  // (3 + 3) * 1
  worst = 0.0;
  for (int i = 0; i < 500; ++i) {
    const double u = t01(rng), v = t01(rng);
    const auto a = c.eval({u}), b = c2.eval({u});
    const auto e = s.eval({(1 - v) * a[0] + v * b[0], (1 - v) * a[1] + v * b[1]});
    const auto g = r.eval({u, v});
    for (int j = 0; j < 4; ++j) worst = std::max(worst, std::abs(e[static_cast<std::size_t>(j)] - g[static_cast<std::size_t>(j)]));
  }
  CHECK(worst < 1e-11);
}

TEST_CASE("a region across knot lines is fitted, with its boundaries on the surface", "[fillet][compose]") {
  std::mt19937 rng(11);
  const KnotVector k = KnotVector(4, {0, 0, 0, 0, 0.5, 1, 1, 1, 1});
  const Surface s = random_bicubic(rng, 3, k, k);
  const Curve a = random_param_curve(rng, 0.1, 0.45), b = random_param_curve(rng, 0.55, 0.9);
  CHECK(fillet::crosses_knot_lines(s, construct::ruled(a, b)));
  CHECK_FALSE(fillet::crosses_knot_lines(s, a));
  CHECK_THROWS_WITH(fillet::subregion(s, a, b, {fillet::SubregionMethod::compose}),
                    Catch::Contains("crosses knot lines") && Catch::Contains("fit"));
  fillet::SubregionReport rep;
  fillet::SubregionOptions o;
  o.tolerance = 1e-6;
  const Surface r = fillet::subregion(s, a, b, o, &rep);
  CHECK_FALSE(rep.composed);
  CHECK(rep.fit_error <= 1e-6);
  std::uniform_real_distribution<double> t01(0.0, 1.0);
  double worst = 0.0, worst_edge = 0.0;
  for (int i = 0; i < 2000; ++i) {
    const double u = t01(rng), v = i % 10 == 0 ? 0.0 : t01(rng);
    const auto pa = a.eval({u}), pb = b.eval({u});
    const auto e = s.eval({(1 - v) * pa[0] + v * pb[0], (1 - v) * pa[1] + v * pb[1]});
    const auto g = r.eval({u, v});
    const double dist = std::hypot(e[0] - g[0], e[1] - g[1], e[2] - g[2]);
    (v == 0.0 ? worst_edge : worst) = std::max(v == 0.0 ? worst_edge : worst, dist);
  }
  CHECK(worst < 2e-6);
  CHECK(worst_edge < 2e-6);
}

TEST_CASE("the dip-0 flend of a right-angled corner is the chamfer plane", "[fillet][blend]") {
  const Corner c;
  const Surface s1 = c.sub1(), s2 = c.sub2();
  fillet::BlendOptions o;
  o.section = fillet::Section::flend;
  o.dip = 0.0;
  const Surface b = fillet::blending_surface(c.input(s1, s2), o);
  double worst = 0.0;
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j) {
      const Vec p = at(b, i / 20.0, j / 20.0);
      worst = std::max(worst, std::abs((p[0] - 2.0) / c.d1 + p[2] / c.d2 - 1.0));
      CHECK(p[1] == Approx(4.0 * i / 20.0).margin(1e-12));
    }
  CHECK(worst < 1e-12);
  // The chamfer runs from rail to rail.
  CHECK(at(b, 0.5, 0.0)[0] == Approx(2.0 + c.d1).margin(1e-12));
  CHECK(at(b, 0.5, 1.0)[2] == Approx(c.d2).margin(1e-12));
}

TEST_CASE("Hermite and flend blends meet both faces G1 on the rails, with no gap", "[fillet][blend]") {
  const Corner c;
  const Surface s1 = c.sub1(), s2 = c.sub2();
  for (const auto section : {fillet::Section::hermite, fillet::Section::flend}) {
    fillet::BlendOptions o;
    o.section = section;
    o.dip = 0.4;
    fillet::BlendReport rep;
    const Surface b = fillet::blending_surface(c.input(s1, s2), o, &rep);
    double angle1 = 0.0, angle2 = 0.0, gap = 0.0;
    for (int i = 0; i <= 50; ++i) {
      const double t = i / 50.0;
      angle1 = std::max(angle1, angle_between_normals(b, t, 0.0, {0, 0, 1}));
      angle2 = std::max(angle2, angle_between_normals(b, t, 1.0, {1, 0, 0}));
      const Vec p = at(b, t, 0.0), q = at(s1, t, 0.0), r = at(b, t, 1.0), w = at(s2, t, 1.0);
      gap = std::max({gap, std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]),
                      std::hypot(r[0] - w[0], r[1] - w[1], r[2] - w[2])});
    }
    CHECK(angle1 < 1e-6);
    CHECK(angle2 < 1e-6);
    CHECK(gap < 1e-12);
    CHECK(rep.angle[0] < 1e-6);
  }
}

TEST_CASE("ruled fillet of the corner: volume of the Hermite section, properties of each face", "[fillet][ruled]") {
  const Corner c;
  const Surface s1 = c.sub1(), s2 = c.sub2();
  fillet::BlendOptions o;
  o.tau = 1.2;
  const Surface b = fillet::blending_surface(c.input(s1, s2), o);
  const auto halves = fillet::ruled_fillet(s1, s2, b);
  // Green's theorem on the Hermite section (X = x - 2, Z = z): the corner's two legs add nothing,
  // so the area is 1/2 int (X Z' - Z X') dv over the cubic; 4-point Gauss is exact (degree 5).
  const double w = std::hypot(c.d1, c.d2), tw = o.tau * w;
  const auto hermite = [&](double v, double& x, double& z, double& dx, double& dz) {
    const double h00 = 2 * v * v * v - 3 * v * v + 1, h01 = -2 * v * v * v + 3 * v * v;
    const double h10 = v * v * v - 2 * v * v + v, h11 = v * v * v - v * v;
    const double d00 = 6 * v * v - 6 * v, d01 = -d00, d10 = 3 * v * v - 4 * v + 1, d11 = 3 * v * v - 2 * v;
    x = c.d1 * h00 - tw * h10;
    dx = c.d1 * d00 - tw * d10;
    z = c.d2 * h01 + tw * h11;
    dz = c.d2 * d01 + tw * d11;
  };
  const auto rule = geom::gauss_legendre(4);
  double area = 0.0;
  for (std::size_t i = 0; i < rule.nodes.size(); ++i) {
    const double v = 0.5 * (rule.nodes[i] + 1.0);
    double x, z, dx, dz;
    hermite(v, x, z, dx, dz);
    area += 0.5 * rule.weights[i] * 0.5 * (x * dz - z * dx);
  }
  CHECK(area > 0.0);
  CHECK(area < 0.5 * c.d1 * c.d2);
  const double volume = geom::volume(halves[0]) + geom::volume(halves[1]);
  CHECK(volume == Approx(4.0 * area).epsilon(1e-9));
  CHECK(geom::signed_volume(halves[0]) > 0.0);
  CHECK(geom::signed_volume(halves[1]) > 0.0);

  // Properties (Sec. 7.1): on S^_1 the floor's 10 + (x - 2) / 4, on S^_2 the wall's 20 + z / 4;
  // on S_b at the rails the same values, and in between within their range.
  for (int i = 0; i <= 10; ++i)
    for (int j = 0; j <= 10; ++j) {
      const double u = i / 10.0, v = j / 10.0;
      const auto p = halves[0].eval({u, v, 0.0});
      CHECK(p[2] == Approx(0.0).margin(1e-12));
      CHECK(p[3] == Approx(10.0 + (p[0] - 2.0) / 4.0).margin(1e-12));
      const auto q = halves[1].eval({u, v, 0.0});
      CHECK(q[0] == Approx(2.0).margin(1e-12));
      CHECK(q[3] == Approx(20.0 + q[2] / 4.0).margin(1e-12));
      const auto top = halves[0].eval({u, v, 1.0});
      CHECK(top[3] >= 10.0 - 1e-12);
      CHECK(top[3] <= 20.0 + c.d2 / 4 + 1e-12);
    }
  for (int i = 0; i <= 10; ++i) {
    CHECK(halves[0].eval({i / 10.0, 0.0, 1.0})[3] == Approx(10.0 + c.d1 / 4.0).margin(1e-12));
    CHECK(halves[1].eval({i / 10.0, 1.0, 1.0})[3] == Approx(20.0 + c.d2 / 4.0).margin(1e-12));
    // The halves glue: the same points on their shared face.
    for (double w2 : {0.0, 0.3, 1.0}) {
      const auto a = halves[0].eval({i / 10.0, 1.0, w2}), d = halves[1].eval({i / 10.0, 0.0, w2});
      CHECK(std::hypot(a[0] - d[0], a[1] - d[1], a[2] - d[2]) < 1e-12);
    }
  }
}

TEST_CASE("blending surfaces refuse parameters out of range", "[fillet][blend]") {
  const Corner c;
  const Surface s1 = c.sub1(), s2 = c.sub2();
  fillet::BlendOptions o;
  o.tau = 0.0;
  CHECK_THROWS_WITH(fillet::blending_surface(c.input(s1, s2), o), Catch::Contains("tau 0; expected"));
  o.tau = 1.0;
  o.section = fillet::Section::flend;
  o.dip = 1.5;
  CHECK_THROWS_WITH(fillet::blending_surface(c.input(s1, s2), o), Catch::Contains("dip 1.5; expected a value in [0, 1]"));
}
