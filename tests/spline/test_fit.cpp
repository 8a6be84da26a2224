// Least-squares fitting and interpolation (trivox/spline/fit.hpp). Expected values come from
// mathematics: a fit reproduces every function of its spline space (polynomials of its degree)
// exactly, interpolation passes through the data, pinned control points are kept bit for bit,
// least squares leaves a residual orthogonal to the space and shrinks it in a finer space.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "trivox/error.hpp"
#include "trivox/spline/fit.hpp"

using namespace trivox::spline;
using trivox::Error;
using trivox::ErrorKind;

namespace {

double uniform(std::mt19937& g, double a, double b) { return std::uniform_real_distribution<double>(a, b)(g); }

std::vector<double> uniform_values(std::mt19937& g, std::size_t n, double a, double b) {
  std::vector<double> x(n);
  for (double& v : x) v = uniform(g, a, b);
  return x;
}

/// n values in [a, b], one in each of n equal parts, shuffled: random, yet no part of the
/// interval left without data (which would make the fit ill-conditioned).
std::vector<double> stratified(std::mt19937& g, int n, double a, double b) {
  std::vector<double> x(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) x[static_cast<std::size_t>(i)] = a + (b - a) * (i + uniform(g, 0.0, 1.0)) / n;
  std::shuffle(x.begin(), x.end(), g);
  return x;
}

/// A polynomial R -> R^dim, sum_a c_a t^a.
struct Poly1 {
  int degree = 0, dim = 0;
  std::vector<double> c;  // (degree + 1) x dim
  std::vector<double> operator()(double t) const {
    std::vector<double> out(static_cast<std::size_t>(dim), 0.0);
    for (int a = degree; a >= 0; --a)
      for (int k = 0; k < dim; ++k) out[k] = out[k] * t + c[static_cast<std::size_t>(a * dim + k)];
    return out;
  }
};

Poly1 random_poly1(std::mt19937& g, int degree, int dim) {
  return {degree, dim, uniform_values(g, static_cast<std::size_t>((degree + 1) * dim), -1.0, 1.0)};
}

/// A polynomial R^2 -> R^dim, sum_{a,b} c_ab u^a v^b.
struct Poly2 {
  int du = 0, dv = 0, dim = 0;
  std::vector<double> c;  // (du + 1) x (dv + 1) x dim
  std::vector<double> operator()(double u, double v) const {
    std::vector<double> out(static_cast<std::size_t>(dim), 0.0);
    for (int a = 0; a <= du; ++a)
      for (int b = 0; b <= dv; ++b)
        for (int k = 0; k < dim; ++k)
          out[k] += c[static_cast<std::size_t>((a * (dv + 1) + b) * dim + k)] * std::pow(u, a) * std::pow(v, b);
    return out;
  }
};

Poly2 random_poly2(std::mt19937& g, int du, int dv, int dim) {
  return {du, dv, dim, uniform_values(g, static_cast<std::size_t>((du + 1) * (dv + 1) * dim), -1.0, 1.0)};
}

/// Samples of f at the parameters, dim values each.
template <class F>
std::vector<double> sample1(const F& f, const std::vector<double>& t) {
  std::vector<double> out;
  for (double x : t) {
    const auto y = f(x);
    out.insert(out.end(), y.begin(), y.end());
  }
  return out;
}

double max_abs(const std::vector<double>& x) {
  double m = 0.0;
  for (double v : x) m = std::max(m, std::abs(v));
  return m;
}

double max_diff(const std::vector<double>& a, const std::vector<double>& b) {
  REQUIRE(a.size() == b.size());
  double m = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(a[i] - b[i]));
  return m;
}

std::vector<double> slice(const std::vector<double>& x, std::size_t j, int dim) {
  return {x.begin() + static_cast<std::ptrdiff_t>(j * dim), x.begin() + static_cast<std::ptrdiff_t>((j + 1) * dim)};
}

/// The error thrown by f (fails the test when none is).
template <class F>
Error error_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e;
  }
  FAIL("expected a trivox::Error");
  return Error("");
}

bool contains(const Error& e, const std::string& fragment) {
  return std::string(e.what()).find(fragment) != std::string::npos;
}

/// Sum of squared distances between the curve and the data.
double residual(const Curve& c, const std::vector<double>& t, const std::vector<double>& y) {
  double r = 0.0;
  const int dim = c.dim();
  for (std::size_t j = 0; j < t.size(); ++j) {
    const auto p = c.eval({t[j]});
    for (int k = 0; k < dim; ++k) r += std::pow(p[k] - y[j * dim + k], 2);
  }
  return r;
}

double residual(const Surface& s, const std::vector<double>& uv, const std::vector<double>& y) {
  double r = 0.0;
  const int dim = s.dim();
  for (std::size_t j = 0; j < uv.size() / 2; ++j) {
    const auto p = s.eval({uv[2 * j], uv[2 * j + 1]});
    for (int k = 0; k < dim; ++k) r += std::pow(p[k] - y[j * dim + k], 2);
  }
  return r;
}

/// Max distance between curve c and f at n points spread over [a, b] (ends included).
template <class F>
double curve_error(const Curve& c, const F& f, double a, double b, int n = 101) {
  double e = 0.0;
  for (int i = 0; i < n; ++i) {
    const double t = a + (b - a) * i / (n - 1);
    e = std::max(e, max_diff(c.eval({t}), f(t)));
  }
  return e;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Parameters and knots

TEST_CASE("fit: chord_length_params accumulates distances", "[spline][fit]") {
  // Legs of length 5, 5 and 10.
  const std::vector<double> pts = {0, 0, 3, 4, 6, 8, 6, 18};
  const auto t = chord_length_params(pts, 2);
  REQUIRE(t.size() == 4);
  CHECK(t[0] == 0.0);
  CHECK(t[1] == Approx(0.25).margin(1e-15));
  CHECK(t[2] == Approx(0.5).margin(1e-15));
  CHECK(t[3] == 1.0);

  const double total = 2 * std::sqrt(5.0) + std::sqrt(10.0);
  const auto c = chord_length_params(pts, 2, 0.5);  // centripetal
  CHECK(c[1] == Approx(std::sqrt(5.0) / total).margin(1e-15));
  CHECK(c[2] == Approx(2 * std::sqrt(5.0) / total).margin(1e-15));

  const auto u = chord_length_params(pts, 2, 0.0);  // uniform
  CHECK(u[1] == Approx(1.0 / 3).margin(1e-15));
  CHECK(u[2] == Approx(2.0 / 3).margin(1e-15));

  const std::vector<double> same = {1, 2, 1, 2, 1, 2};
  CHECK(error_of([&] { chord_length_params(same, 2); }).kind() == ErrorKind::bad_input);
  CHECK(error_of([&] { chord_length_params(std::vector<double>{1, 2, 3}, 2); }).kind() == ErrorKind::bad_input);
}

TEST_CASE("fit: interpolation_knots average the parameters (NURBS Book Ex. 9.1)", "[spline][fit]") {
  // Example 9.1: parameters 0, 5/17, 9/17, 14/17, 1, degree 3 -> one interior knot 28/51.
  const std::vector<double> t = {0, 5.0 / 17, 9.0 / 17, 14.0 / 17, 1};
  const KnotVector k = interpolation_knots(t, 4);
  REQUIRE(k.size() == 5);
  CHECK(k.order() == 4);
  const std::vector<double> expected = {0, 0, 0, 0, 28.0 / 51, 1, 1, 1, 1};
  for (std::size_t i = 0; i < expected.size(); ++i) CHECK(k[static_cast<int>(i)] == Approx(expected[i]).margin(1e-15));

  // Unordered parameters give the same knots.
  const std::vector<double> shuffled = {9.0 / 17, 1, 0, 14.0 / 17, 5.0 / 17};
  CHECK(interpolation_knots(shuffled, 4) == k);

  // Order 2: the parameters themselves; order 1: midpoints.
  CHECK(interpolation_knots(t, 2).knots() == std::vector<double>{0, 0, 5.0 / 17, 9.0 / 17, 14.0 / 17, 1, 1});
  const auto k1 = interpolation_knots(t, 1).knots();
  REQUIRE(k1.size() == 6);
  CHECK(k1[1] == Approx(2.5 / 17).margin(1e-15));
  CHECK(k1[4] == Approx((14.0 / 17 + 1) / 2).margin(1e-15));

  CHECK(error_of([&] { interpolation_knots(std::vector<double>{0, 1}, 3); }).kind() == ErrorKind::bad_input);
  CHECK(error_of([&] { interpolation_knots(std::vector<double>{2, 2, 2}, 2); }).kind() == ErrorKind::bad_input);
}

TEST_CASE("fit: fitting_knots put a parameter in every knot span", "[spline][fit]") {
  std::mt19937 g(7);
  auto t = uniform_values(g, 57, -1.0, 3.0);
  for (int order = 1; order <= 5; ++order)
    for (int count : {order, order + 1, 10, 30, 57}) {
      const KnotVector k = fitting_knots(t, order, count);
      REQUIRE(k.size() == count);
      CHECK(k.front() == *std::min_element(t.begin(), t.end()));
      CHECK(k.back() == *std::max_element(t.begin(), t.end()));
      for (int mu = order - 1; mu < k.size(); ++mu) {
        if (!(k[mu] < k[mu + 1])) continue;
        const bool last = mu + 1 == k.size();
        CHECK(std::any_of(t.begin(), t.end(), [&](double x) { return x >= k[mu] && (x < k[mu + 1] || last); }));
      }
    }
  CHECK(error_of([&] { fitting_knots(t, 4, 58); }).kind() == ErrorKind::bad_input);
  CHECK(error_of([&] { fitting_knots(t, 4, 3); }).kind() == ErrorKind::bad_input);
}

// ---------------------------------------------------------------------------------------------
// Curves

TEST_CASE("fit: fit_curve reproduces polynomials of its degree", "[spline][fit]") {
  std::mt19937 g(11);
  for (int order = 1; order <= 6; ++order) {
    CAPTURE(order);
    const int dim = 3;
    const Poly1 f = random_poly1(g, order - 1, dim);
    // Interior knots of every multiplicity up to order - 1 (a discontinuity would still hold f).
    std::vector<double> k(static_cast<std::size_t>(order), -1.0);
    for (double x : {-0.4, 0.3}) k.push_back(x);
    for (int r = 0; r < std::max(1, order - 1); ++r) k.push_back(0.7);
    k.push_back(1.1);
    k.insert(k.end(), static_cast<std::size_t>(order), 2.0);
    const KnotVector knots(order, k);
    auto t = uniform_values(g, 300, -1.0, 2.0);  // unordered
    t.push_back(-1.0);
    t.push_back(2.0);
    const Curve c = fit_curve(t, dim, sample1(f, t), knots);
    CHECK(c.count(0) == knots.size());
    const double scale = max_abs(sample1(f, uniform_values(g, 50, -1.0, 2.0)));
    CHECK(curve_error(c, f, -1.0, 2.0, 257) <= 1e-12 * scale);
  }
}

TEST_CASE("fit: interpolate_curve passes through the data", "[spline][fit]") {
  std::mt19937 g(12);
  for (int order = 1; order <= 6; ++order) {
    CAPTURE(order);
    const int dim = 2, m = 25;
    const auto pts = uniform_values(g, m * dim, -5.0, 5.0);  // arbitrary points, no polynomial
    auto t = chord_length_params(pts, dim, order == 3 ? 0.5 : 1.0);
    const Curve c = interpolate_curve(t, dim, pts, order);
    REQUIRE(c.count(0) == m);
    for (int j = 0; j < m; ++j) CHECK(max_diff(c.eval({t[j]}), slice(pts, j, dim)) <= 1e-12 * max_abs(pts));

    // The data in another order give the same curve (up to rounding).
    std::vector<int> perm(m);
    std::iota(perm.begin(), perm.end(), 0);
    std::shuffle(perm.begin(), perm.end(), g);
    std::vector<double> t2, pts2;
    for (int j : perm) {
      t2.push_back(t[j]);
      const auto p = slice(pts, j, dim);
      pts2.insert(pts2.end(), p.begin(), p.end());
    }
    const Curve c2 = interpolate_curve(t2, dim, pts2, c.knots(0));
    const std::vector<double> a(c.points().begin(), c.points().end()), b(c2.points().begin(), c2.points().end());
    CHECK(max_diff(a, b) <= 1e-10 * max_abs(pts));
  }
}

TEST_CASE("fit: interpolating a polynomial of the curve's degree gives the polynomial", "[spline][fit]") {
  std::mt19937 g(13);
  for (int order = 2; order <= 5; ++order) {
    const Poly1 f = random_poly1(g, order - 1, 4);
    auto t = uniform_values(g, 12, 0.0, 3.0);
    const Curve c = interpolate_curve(t, 4, sample1(f, t), order);
    const double a = c.domain(0)[0], b = c.domain(0)[1];
    CHECK(curve_error(c, f, a, b) <= 1e-12 * max_abs(sample1(f, t)));
  }
}

TEST_CASE("fit: fit_curve keeps pinned control points exactly", "[spline][fit]") {
  std::mt19937 g(14);
  const int dim = 3;
  const KnotVector knots = KnotVector::uniform(4, 6, 0.0, 1.0);
  const auto t = uniform_values(g, 80, 0.0, 1.0);
  std::vector<double> y;
  for (double x : t) y.insert(y.end(), {std::sin(4 * x), std::cos(3 * x), x * x + uniform(g, -0.1, 0.1)});

  CurvePins pins = CurvePins::ends(knots.size(), std::vector<double>{0.25, -1.5, 3.0}, std::vector<double>{7, 8, 9});
  pins.rows.push_back(4);
  pins.points.insert(pins.points.end(), {-2.0, 0.125, 1e3});
  const Curve c = fit_curve(t, dim, y, knots, pins);
  for (std::size_t r = 0; r < pins.rows.size(); ++r)
    for (int k = 0; k < dim; ++k) CHECK(c.point(pins.rows[r])[k] == pins.points[r * dim + k]);
  // A clamped curve starts and ends at its end control points.
  CHECK(max_diff(c.eval({0.0}), {0.25, -1.5, 3.0}) <= 1e-14);
  CHECK(max_diff(c.eval({1.0}), {7, 8, 9}) <= 1e-14);

  // Every control point pinned: nothing to fit, no data needed beyond the checks.
  CurvePins all;
  for (int l = 0; l < knots.size(); ++l) {
    all.rows.push_back(l);
    all.points.insert(all.points.end(), {1.0 * l, 2.0, 3.0});
  }
  const Curve d = fit_curve(t, dim, y, knots, all);
  CHECK(std::vector<double>(d.points().begin(), d.points().end()) == all.points);
}

TEST_CASE("fit: fit_curve with the polynomial's own end points still reproduces it", "[spline][fit]") {
  std::mt19937 g(15);
  const Poly1 f = random_poly1(g, 3, 2);
  const KnotVector knots(4, {-2, -2, -2, -2, -1, 0, 0.5, 2, 2, 2, 2});
  const auto t = uniform_values(g, 40, -2.0, 2.0);
  const Curve c = fit_curve(t, 2, sample1(f, t), knots, CurvePins::ends(knots.size(), f(-2.0), f(2.0)));
  CHECK(curve_error(c, f, -2.0, 2.0) <= 1e-12 * max_abs(sample1(f, t)));
}

TEST_CASE("fit: least squares is orthogonal to the space and improves with refinement", "[spline][fit]") {
  std::mt19937 g(16);
  const int dim = 2;
  const auto t = uniform_values(g, 200, 0.0, 1.0);
  std::vector<double> y;
  for (double x : t) y.insert(y.end(), {std::sin(6 * x) + uniform(g, -0.05, 0.05), std::exp(x) * std::cos(9 * x)});

  const KnotVector coarse = KnotVector::uniform(4, 4);
  const KnotVector fine = KnotVector::uniform(4, 8);  // holds the coarse space
  const Curve cc = fit_curve(t, dim, y, coarse);
  const Curve cf = fit_curve(t, dim, y, fine);
  const double rc = residual(cc, t, y), rf = residual(cf, t, y);
  CHECK(rf < rc);

  // Normal equations: sum_j N_l(t_j) (C(t_j) - y_j) = 0 for every control point l.
  const KnotVector& k = fine;
  std::vector<double> grad(static_cast<std::size_t>(k.size() * dim), 0.0), N(4);
  for (std::size_t j = 0; j < t.size(); ++j) {
    const int mu = k.find_span(t[j]);
    k.basis(mu, t[j], N.data());
    const auto p = cf.eval({t[j]});
    for (int a = 0; a < 4; ++a)
      for (int c = 0; c < dim; ++c) grad[(mu - 3 + a) * dim + c] += N[a] * (p[c] - y[j * dim + c]);
  }
  CHECK(max_abs(grad) <= 1e-11 * static_cast<double>(t.size()) * max_abs(y));

  // Pinning control points can only raise the residual.
  const Curve cp = fit_curve(t, dim, y, fine, CurvePins::ends(fine.size(), std::vector<double>{0, 0}, std::vector<double>{0, 0}));
  CHECK(residual(cp, t, y) >= rf);
}

TEST_CASE("fit: under-determined curve systems are reported", "[spline][fit]") {
  const KnotVector knots = KnotVector::uniform(3, 5);  // 7 control points
  std::vector<double> t = {0.0, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0};
  const auto y = [](const std::vector<double>& p) { return std::vector<double>(p.size(), 1.0); };

  SECTION("fewer data than control points") {
    std::vector<double> few(t.begin(), t.begin() + 6);
    const Error e = error_of([&] { fit_curve(few, 1, y(few), knots); });
    CHECK(e.kind() == ErrorKind::bad_input);
    CHECK(contains(e, "expected at least one parameter per free control point"));
  }
  SECTION("enough data, none where a basis function lives (Schoenberg-Whitney)") {
    std::vector<double> left = {0.0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.39};
    const Error e = error_of([&] { fit_curve(left, 1, y(left), knots); });
    CHECK(e.kind() == ErrorKind::bad_input);
    CHECK(contains(e, "Schoenberg-Whitney"));
    CHECK(contains(e, "control point 4 is not determined"));
  }
  SECTION("interpolation at a repeated parameter") {
    std::vector<double> rep = {0.0, 0.1, 0.3, 0.3, 0.5, 0.7, 1.0};
    const Error e = error_of([&] { interpolate_curve(rep, 1, y(rep), knots); });
    CHECK(e.kind() == ErrorKind::bad_input);
    CHECK(contains(e, "Schoenberg-Whitney"));
  }
  SECTION("interpolation needs one parameter per control point") {
    const Error e = error_of([&] { interpolate_curve(std::vector<double>(t.begin(), t.end() - 1), 1, y(t), knots); });
    CHECK(e.kind() == ErrorKind::bad_input);
  }
  SECTION("a parameter outside the domain") {
    t[3] = 1.5;
    const Error e = error_of([&] { fit_curve(t, 1, y(t), knots); });
    CHECK(e.kind() == ErrorKind::bad_input);
    CHECK(contains(e, "parameter 3 is 1.5"));
  }
  SECTION("an empty knot vector") {
    CHECK(contains(error_of([&] { fit_curve(t, 1, y(t), KnotVector()); }), "knot vector is empty"));
  }
  SECTION("values and pins of the wrong size") {
    CHECK(error_of([&] { fit_curve(t, 2, y(t), knots); }).kind() == ErrorKind::bad_input);
    CurvePins bad{{7}, {0.0}};
    CHECK(contains(error_of([&] { fit_curve(t, 1, y(t), knots, bad); }), "pinned control point index 7"));
    CurvePins twice{{1, 1}, {0.0, 0.0}};
    CHECK(error_of([&] { fit_curve(t, 1, y(t), knots, twice); }).kind() == ErrorKind::bad_input);
  }
  SECTION("pinning frees data: 5 parameters for 5 free control points") {
    std::vector<double> five = {0.1, 0.3, 0.5, 0.7, 0.9};
    const Curve c = fit_curve(five, 1, y(five), knots, CurvePins::ends(7, std::vector<double>{1}, std::vector<double>{1}));
    CHECK(curve_error(c, [](double) { return std::vector<double>{1.0}; }, 0, 1) <= 1e-13);
  }
}

// ---------------------------------------------------------------------------------------------
// Surfaces

namespace {

/// Max distance between surface s and f on an n x n grid over its domain.
template <class F>
double surface_error(const Surface& s, const F& f, int n = 31) {
  const auto du = s.domain(0), dv = s.domain(1);
  double e = 0.0;
  for (int b = 0; b < n; ++b)
    for (int a = 0; a < n; ++a) {
      const double u = du[0] + (du[1] - du[0]) * a / (n - 1), v = dv[0] + (dv[1] - dv[0]) * b / (n - 1);
      e = std::max(e, max_diff(s.eval({u, v}), f(u, v)));
    }
  return e;
}

/// Grid samples, u fastest.
template <class F>
std::vector<double> sample_grid(const F& f, const std::vector<double>& u, const std::vector<double>& v) {
  std::vector<double> out;
  for (double y : v)
    for (double x : u) {
      const auto p = f(x, y);
      out.insert(out.end(), p.begin(), p.end());
    }
  return out;
}

template <class F>
std::vector<double> sample_scattered(const F& f, const std::vector<double>& uv) {
  std::vector<double> out;
  for (std::size_t j = 0; j < uv.size() / 2; ++j) {
    const auto p = f(uv[2 * j], uv[2 * j + 1]);
    out.insert(out.end(), p.begin(), p.end());
  }
  return out;
}

std::vector<double> scattered_uv(std::mt19937& g, int m, std::array<double, 4> box) {
  std::vector<double> uv;
  for (int j = 0; j < m; ++j) uv.insert(uv.end(), {uniform(g, box[0], box[1]), uniform(g, box[2], box[3])});
  return uv;
}

std::array<KnotVector, 2> test_knots() {
  return {KnotVector(4, {0, 0, 0, 0, 0.4, 0.9, 0.9, 1.5, 2, 2, 2, 2}),
          KnotVector(3, {-1, -1, -1, -0.5, 0.25, 1, 1, 1})};
}

}  // namespace

TEST_CASE("fit: fit_surface reproduces polynomials of its degree from scattered data", "[spline][fit]") {
  std::mt19937 g(21);
  // Orders (4, 3) with more control points in u, and (3, 4) with more in v (the solver numbers
  // the unknowns either way round, whichever gives the smaller band).
  const std::array<std::array<KnotVector, 2>, 2> spaces = {
      test_knots(), std::array<KnotVector, 2>{KnotVector::uniform(3, 2, 0, 2), KnotVector::uniform(4, 6, -1, 1)}};
  for (const auto& knots : spaces) {
    const Poly2 f = random_poly2(g, knots[0].degree(), knots[1].degree(), 2);
    const auto uv = scattered_uv(g, 600, {0, 2, -1, 1});
    const auto y = sample_scattered(f, uv);
    const Surface s = fit_surface(uv, 2, y, knots);
    CHECK(s.counts() == std::array<int, 2>{knots[0].size(), knots[1].size()});
    CHECK(surface_error(s, f) <= 1e-12 * max_abs(y));
  }
}

TEST_CASE("fit: fit_surface_grid reproduces polynomials and interpolates grids", "[spline][fit]") {
  std::mt19937 g(22);
  const auto knots = test_knots();
  const Poly2 f = random_poly2(g, 3, 2, 3);
  auto u = stratified(g, 17, 0.0, 2.0);  // unordered
  auto v = stratified(g, 11, -1.0, 1.0);
  u.push_back(2.0);
  v.push_back(-1.0);
  const auto y = sample_grid(f, u, v);
  const Surface s = fit_surface_grid(u, v, 3, y, knots);
  CHECK(surface_error(s, f) <= 1e-12 * max_abs(y));

  // Interpolation: as many grid lines as control points, any data.
  const auto z = uniform_values(g, u.size() * v.size() * 2, -1.0, 1.0);
  const Surface t = interpolate_surface_grid(u, v, 2, z, {4, 3});
  REQUIRE(t.counts() == std::array<int, 2>{static_cast<int>(u.size()), static_cast<int>(v.size())});
  double err = 0.0;
  for (std::size_t b = 0; b < v.size(); ++b)
    for (std::size_t a = 0; a < u.size(); ++a)
      err = std::max(err, max_diff(t.eval({u[a], v[b]}), slice(z, a + u.size() * b, 2)));
  CHECK(err <= 1e-12);
}

TEST_CASE("fit: gridded and scattered least squares agree on gridded data", "[spline][fit]") {
  // Both minimise the same sum of squares, whose minimiser is unique: the same control points.
  std::mt19937 g(23);
  const auto knots = test_knots();
  auto u = stratified(g, 14, 0.0, 2.0), v = stratified(g, 9, -1.0, 1.0);
  u.insert(u.end(), {0.0, 2.0});
  v.insert(v.end(), {-1.0, 1.0});
  const auto noisy = [&](double x, double w) {
    return std::vector<double>{std::sin(2 * x) * w, std::cos(3 * w) + x};
  };
  auto y = sample_grid(noisy, u, v);
  for (double& x : y) x += uniform(g, -0.1, 0.1);
  std::vector<double> uv;
  for (double w : v)
    for (double x : u) uv.insert(uv.end(), {x, w});

  SurfacePins pins;
  pins.rows[SurfacePins::v1] = uniform_values(g, 8 * 2, -1.0, 1.0);
  pins.rows[SurfacePins::u0] = uniform_values(g, 5 * 2, -1.0, 1.0);
  pins.rows[SurfacePins::u0][8] = pins.rows[SurfacePins::v1][0];  // corner (0, 4)
  pins.rows[SurfacePins::u0][9] = pins.rows[SurfacePins::v1][1];
  for (const SurfacePins& p : {SurfacePins{}, pins}) {
    const Surface a = fit_surface_grid(u, v, 2, y, knots, p);
    const Surface b = fit_surface(uv, 2, y, knots, p);
    const std::vector<double> pa(a.points().begin(), a.points().end()), pb(b.points().begin(), b.points().end());
    CHECK(max_diff(pa, pb) <= 1e-10);
  }
}

TEST_CASE("fit: a finer surface space fits noisy data no worse", "[spline][fit]") {
  std::mt19937 g(24);
  const auto uv = scattered_uv(g, 500, {0, 1, 0, 1});
  std::vector<double> y;
  for (std::size_t j = 0; j < uv.size() / 2; ++j)
    y.push_back(std::sin(5 * uv[2 * j]) * std::cos(4 * uv[2 * j + 1]) + uniform(g, -0.02, 0.02));
  const Surface coarse = fit_surface(uv, 1, y, {KnotVector::uniform(3, 2), KnotVector::uniform(3, 2)});
  const Surface fine = fit_surface(uv, 1, y, {KnotVector::uniform(3, 4), KnotVector::uniform(3, 4)});
  CHECK(residual(fine, uv, y) < residual(coarse, uv, y));
}

TEST_CASE("fit: pinned boundary curves are reproduced exactly on the boundary", "[spline][fit]") {
  std::mt19937 g(25);
  const std::array<KnotVector, 2> knots = {KnotVector(4, {0, 0, 0, 0, 0.25, 0.5, 0.5, 0.75, 1, 1, 1, 1}),
                                           KnotVector(3, {0, 0, 0, 1.0 / 3, 2.0 / 3, 1, 1, 1})};
  const int dim = 3;
  // Corners P(u, v), then boundary curves through them, each in the surface's space but not
  // necessarily on its knots: v0 a quadratic with a knot at 0.5 (the double knot holds it),
  // u0 a straight line, v1 and u1 on the surface's own knots.
  const auto P00 = uniform_values(g, dim, -1, 1), P10 = uniform_values(g, dim, -1, 1);
  const auto P01 = uniform_values(g, dim, -1, 1), P11 = uniform_values(g, dim, -1, 1);
  const auto curve = [&](const KnotVector& k, const std::vector<double>& a, const std::vector<double>& b) {
    auto pts = uniform_values(g, static_cast<std::size_t>(k.size() * dim), -1, 1);
    std::copy(a.begin(), a.end(), pts.begin());
    std::copy(b.begin(), b.end(), pts.end() - dim);
    return Curve({k}, dim, pts);
  };
  SurfacePins pins;
  pins.curves[SurfacePins::v0] = curve(KnotVector(3, {0, 0, 0, 0.5, 1, 1, 1}), P00, P10);
  pins.curves[SurfacePins::v1] = curve(knots[0], P01, P11);
  pins.curves[SurfacePins::u0] = curve(KnotVector::bezier(2), P00, P01);
  pins.curves[SurfacePins::u1] = curve(knots[1], P10, P11);

  const auto field = [](double u, double v) {
    return std::vector<double>{u + 0.1 * std::sin(7 * v), v * v - u, std::cos(3 * u * v)};
  };
  const auto uv = scattered_uv(g, 400, {0, 1, 0, 1});
  auto gu = stratified(g, 20, 0, 1), gv = stratified(g, 15, 0, 1);
  gu.insert(gu.end(), {0.0, 1.0});
  gv.insert(gv.end(), {0.0, 1.0});
  const Surface scattered = fit_surface(uv, dim, sample_scattered(field, uv), knots, pins);
  const Surface gridded = fit_surface_grid(gu, gv, dim, sample_grid(field, gu, gv), knots, pins);

  for (const Surface* s : {&scattered, &gridded}) {
    double err = 0.0;
    for (int i = 0; i <= 64; ++i) {
      const double x = i / 64.0;
      err = std::max(err, max_diff(s->eval({x, 0.0}), pins.curves[SurfacePins::v0]->eval({x})));
      err = std::max(err, max_diff(s->eval({x, 1.0}), pins.curves[SurfacePins::v1]->eval({x})));
      err = std::max(err, max_diff(s->eval({0.0, x}), pins.curves[SurfacePins::u0]->eval({x})));
      err = std::max(err, max_diff(s->eval({1.0, x}), pins.curves[SurfacePins::u1]->eval({x})));
    }
    CHECK(err <= 1e-13);
  }
}

TEST_CASE("fit: pinned boundary rows are kept exactly and polynomials still reproduced", "[spline][fit]") {
  std::mt19937 g(26);
  const auto knots = test_knots();  // clamped, 8 x 5 control points
  const Poly2 f = random_poly2(g, 3, 2, 2);
  // The polynomial's boundary curves, as interpolants in the surface's spaces (exact: they lie
  // in them), pinned on all four sides.
  const auto iso = [&](int side) {
    const KnotVector& k = knots[side < 2 ? 1 : 0];
    const double end = side < 2 ? (side == 0 ? 0.0 : 2.0) : (side == 2 ? -1.0 : 1.0);
    const auto t = k.greville();
    std::vector<double> y;
    for (double x : t) {
      const auto p = side < 2 ? f(end, x) : f(x, end);
      y.insert(y.end(), p.begin(), p.end());
    }
    return interpolate_curve(t, 2, y, k);
  };
  SurfacePins pins;
  for (int s = 0; s < 4; ++s) pins.curves[s] = iso(s);
  const auto uv = scattered_uv(g, 300, {0, 2, -1, 1});
  const Surface s = fit_surface(uv, 2, sample_scattered(f, uv), knots, pins);
  CHECK(surface_error(s, f) <= 1e-12 * max_abs(sample_scattered(f, uv)));

  // Explicit rows: kept bit for bit.
  SurfacePins rows;
  rows.rows[SurfacePins::u1] = uniform_values(g, 5 * 2, -3, 3);
  rows.rows[SurfacePins::v0] = uniform_values(g, 8 * 2, -3, 3);
  rows.rows[SurfacePins::v0][14] = rows.rows[SurfacePins::u1][0];  // corner (7, 0)
  rows.rows[SurfacePins::v0][15] = rows.rows[SurfacePins::u1][1];
  auto u = stratified(g, 12, 0, 2), v = stratified(g, 9, -1, 1);
  u.insert(u.end(), {0.0, 2.0});
  v.insert(v.end(), {-1.0, 1.0});
  const Surface a = fit_surface_grid(u, v, 2, sample_grid(f, u, v), knots, rows);
  const Surface b = fit_surface(uv, 2, sample_scattered(f, uv), knots, rows);
  for (const Surface* t : {&a, &b}) {
    for (int j = 0; j < 5; ++j)
      for (int c = 0; c < 2; ++c) CHECK(t->point(t->row({7, j}))[c] == rows.rows[SurfacePins::u1][j * 2 + c]);
    for (int i = 0; i < 8; ++i)
      for (int c = 0; c < 2; ++c) CHECK(t->point(t->row({i, 0}))[c] == rows.rows[SurfacePins::v0][i * 2 + c]);
  }
}

TEST_CASE("fit: bad surface pins are reported", "[spline][fit]") {
  std::mt19937 g(27);
  const auto knots = test_knots();
  const auto uv = scattered_uv(g, 200, {0, 2, -1, 1});
  const std::vector<double> y(200, 1.0);
  const auto fails = [&](const SurfacePins& p) { return error_of([&] { fit_surface(uv, 1, y, knots, p); }); };

  SECTION("a curve outside the surface's space") {
    SurfacePins p;
    p.curves[SurfacePins::v0] = Curve({KnotVector(3, {0, 0, 0, 0.3, 2, 2, 2})}, 1, {0, 1, 2, 3});
    const Error e = fails(p);
    CHECK(e.kind() == ErrorKind::bad_input);
    CHECK(contains(e, "does not lie in the surface's u space"));
  }
  SECTION("a curve on another domain") {
    SurfacePins p;
    p.curves[SurfacePins::u1] = Curve({KnotVector::bezier(2, 0, 1)}, 1, {0, 1});
    CHECK(contains(fails(p), "expected the surface's v domain [-1, 1]"));
  }
  SECTION("a curve of another dimension") {
    SurfacePins p;
    p.curves[SurfacePins::u1] = Curve({KnotVector::bezier(2, -1, 1)}, 2, {0, 1, 2, 3});
    CHECK(contains(fails(p), "boundary curve u1 has 2 coordinates"));
  }
  SECTION("a rational curve") {
    SurfacePins p;
    p.curves[SurfacePins::u0] = Curve({KnotVector::bezier(3, -1, 1)}, 1, {0, 1, 2}, {1, 2, 1});
    CHECK(contains(fails(p), "rational"));
  }
  SECTION("corners that disagree") {
    SurfacePins p;
    p.curves[SurfacePins::u0] = Curve({KnotVector::bezier(2, -1, 1)}, 1, {0, 1});
    p.curves[SurfacePins::v0] = Curve({KnotVector::bezier(2, 0, 2)}, 1, {0.5, 1});
    CHECK(contains(fails(p), "disagree at control point (0, 0)"));
  }
  SECTION("a side pinned twice, or a row of the wrong size") {
    SurfacePins p;
    p.curves[SurfacePins::u0] = Curve({KnotVector::bezier(2, -1, 1)}, 1, {0, 1});
    p.rows[SurfacePins::u0] = std::vector<double>(5, 0.0);
    CHECK(contains(fails(p), "both a curve and control rows"));
    SurfacePins q;
    q.rows[SurfacePins::v1] = std::vector<double>(5, 0.0);
    CHECK(contains(fails(q), "expected 8 control points"));
  }
  SECTION("a curve pin across unclamped knots") {
    const std::array<KnotVector, 2> open = {KnotVector(3, {-0.5, -0.25, 0, 1, 2, 2.5, 3}), knots[1]};
    SurfacePins p;
    p.curves[SurfacePins::u0] = Curve({KnotVector::bezier(2, -1, 1)}, 1, {0, 1});
    const Error e = error_of([&] { fit_surface(uv, 1, y, open, p); });
    CHECK(contains(e, "not clamped at the start"));
  }
}

TEST_CASE("fit: under-determined surface systems are reported", "[spline][fit]") {
  std::mt19937 g(28);
  const auto knots = test_knots();

  SECTION("scattered data on one iso-line") {
    std::vector<double> uv;
    for (int j = 0; j < 200; ++j) uv.insert(uv.end(), {uniform(g, 0, 2), 0.1});
    // Every control point acts on v = 0.1, yet the data cannot tell the two v rows apart.
    const std::array<KnotVector, 2> linear_v = {knots[0], KnotVector::bezier(2, -1, 1)};
    const Error e = error_of([&] { fit_surface(uv, 1, std::vector<double>(200, 1.0), linear_v); });
    CHECK(e.kind() == ErrorKind::bad_input);
    CHECK(contains(e, "rank"));
  }
  SECTION("scattered data missing from a control point's support") {
    const auto uv = scattered_uv(g, 300, {0, 0.35, -1, 1});
    const Error e = error_of([&] { fit_surface(uv, 1, std::vector<double>(300, 1.0), knots); });
    CHECK(e.kind() == ErrorKind::bad_input);
    CHECK(contains(e, "no data point lies where control point (4, 0) acts"));
  }
  SECTION("too few scattered data") {
    const auto uv = scattered_uv(g, 39, {0, 2, -1, 1});
    CHECK(error_of([&] { fit_surface(uv, 1, std::vector<double>(39, 1.0), knots); }).kind() == ErrorKind::bad_input);
  }
  SECTION("a grid with no v parameter near the end") {
    const auto u = uniform_values(g, 10, 0, 2), v = uniform_values(g, 10, -1, 0.2);
    const Error e = error_of([&] { fit_surface_grid(u, v, 1, std::vector<double>(100, 1.0), knots); });
    CHECK(e.kind() == ErrorKind::bad_input);
    CHECK(contains(e, "control point 4 in v"));
    CHECK(contains(e, "Schoenberg-Whitney"));
  }
  SECTION("a grid value array of the wrong size") {
    const auto u = uniform_values(g, 10, 0, 2), v = uniform_values(g, 10, -1, 1);
    CHECK(error_of([&] { fit_surface_grid(u, v, 2, std::vector<double>(100, 1.0), knots); }).kind() ==
          ErrorKind::bad_input);
  }
}
