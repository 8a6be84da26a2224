// Evaluation: B-splines reproduce polynomials exactly (values and partial derivatives up to the
// second order), rational splines equal the quotient of their homogeneous polynomials, and the
// coherent Evaluator equals the plain evaluation.
#include <catch2/catch.hpp>

#include <cmath>

#include "poly.hpp"
#include "trivox/error.hpp"
#include "trivox/spline/evaluator.hpp"
#include "trivox/spline/tensor_spline.hpp"

using namespace trivox::spline;
using trivox::test::TensorPoly;
using trivox::test::test_knots;

namespace {

template <int P>
void check_polynomial(std::array<int, P> orders, int dim, unsigned seed) {
  std::array<int, P> deg{};
  std::array<KnotVector, P> knots;
  for (int d = 0; d < P; ++d) {
    deg[static_cast<std::size_t>(d)] = orders[static_cast<std::size_t>(d)] - 1;
    knots[static_cast<std::size_t>(d)] = test_knots(orders[static_cast<std::size_t>(d)], seed + static_cast<unsigned>(d), -0.5, 1.5);
  }
  const auto f = TensorPoly<P>::random(deg, dim, seed);
  const auto s = f.spline(knots);
  const int nd = derivative_count(P, 2);
  const auto alphas = derivative_multi_indices<P>(2);
  REQUIRE(static_cast<int>(alphas.size()) == nd);
  double worst = 0.0;
  int worst_k = 0;
  for (const auto& t : trivox::test::random_params(s, 300, seed)) {
    const auto v = s.eval_derivatives(t, 2);
    const auto p = s.eval(t);
    for (int k = 0; k < nd; ++k)
      for (int h = 0; h < dim; ++h) {
        const double exact = f.derivative(t, alphas[static_cast<std::size_t>(k)], h);
        const double dev = std::abs(v[static_cast<std::size_t>(k * dim + h)] - exact) / (1.0 + std::abs(exact));
        if (dev > worst) { worst = dev; worst_k = k; }
        if (k == 0) worst = std::max(worst, std::abs(p[static_cast<std::size_t>(h)] - exact) / (1.0 + std::abs(exact)));
      }
  }
  INFO("P = " << P << ", dim = " << dim << ", worst relative deviation " << worst << " in derivative " << worst_k);
  CHECK(worst < 1e-11);
}

}  // namespace

TEST_CASE("curves, surfaces and trivariates reproduce polynomials with their derivatives") {
  check_polynomial<1>({1}, 2, 1);
  check_polynomial<1>({2}, 1, 2);
  check_polynomial<1>({4}, 3, 3);
  check_polynomial<1>({6}, 2, 4);
  check_polynomial<2>({3, 4}, 3, 5);
  check_polynomial<2>({2, 2}, 1, 6);
  check_polynomial<3>({4, 4, 4}, 6, 7);  // tricubic, xyz + rgb
  check_polynomial<3>({2, 3, 4}, 3, 8);
  check_polynomial<3>({4, 4, 4}, 11, 9);  // more coordinates than the unrolled kernels
  check_polynomial<3>({1, 2, 2}, 1, 10);
}

TEST_CASE("the derivative multi-indices are ordered by total order") {
  const auto a = derivative_multi_indices<3>(2);
  REQUIRE(a.size() == 10);
  CHECK(a[1] == std::array<int, 3>{1, 0, 0});
  CHECK(a[3] == std::array<int, 3>{0, 0, 1});
  CHECK(a[5] == std::array<int, 3>{1, 1, 0});
  CHECK(a[9] == std::array<int, 3>{0, 0, 2});
  CHECK(derivative_slot<3>({0, 1, 1}) == 8);
  CHECK(derivative_count(2, 2) == 6);
  CHECK(derivative_count(1, 1) == 2);
}

TEST_CASE("a rational quadratic is the exact quarter circle, with exact derivatives") {
  // P0 = (1,0), P1 = (1,1), P2 = (0,1), weights 1, 1/sqrt2, 1: x = N_x / D, y = N_y / D with
  // Bernstein polynomials N_x = (1-t)^2 + c 2t(1-t), N_y = c 2t(1-t) + t^2, D = (1-t)^2 + c 2t(1-t) + t^2.
  const double c = std::sqrt(0.5);
  const Curve arc({KnotVector::bezier(3)}, 2, {1, 0, 1, 1, 0, 1}, {1, c, 1});
  for (int i = 0; i <= 50; ++i) {
    const double t = i / 50.0;
    const double Nx = (1 - t) * (1 - t) + 2 * c * t * (1 - t), Ny = 2 * c * t * (1 - t) + t * t;
    const double D = (1 - t) * (1 - t) + 2 * c * t * (1 - t) + t * t;
    const double dNx = -2 * (1 - t) + 2 * c * (1 - 2 * t), dNy = 2 * c * (1 - 2 * t) + 2 * t;
    const double dD = -2 * (1 - t) + 2 * c * (1 - 2 * t) + 2 * t;
    const double ddNx = 2 - 4 * c, ddNy = -4 * c + 2, ddD = 2 - 4 * c + 2;
    const auto v = arc.eval_derivatives({t}, 2);
    CHECK(std::hypot(v[0], v[1]) == Approx(1.0).epsilon(1e-15));
    CHECK(v[0] == Approx(Nx / D).epsilon(1e-14));
    const double dx = (dNx * D - Nx * dD) / (D * D), dy = (dNy * D - Ny * dD) / (D * D);
    CHECK(v[2] == Approx(dx).margin(1e-13));
    CHECK(v[3] == Approx(dy).margin(1e-13));
    // (f/D)'' = (f'' - 2 D' (f/D)' - D'' (f/D)) / D
    const double ddx = (ddNx - 2 * dD * dx - ddD * Nx / D) / D, ddy = (ddNy - 2 * dD * dy - ddD * Ny / D) / D;
    CHECK(v[4] == Approx(ddx).margin(1e-12));
    CHECK(v[5] == Approx(ddy).margin(1e-12));
  }
}

TEST_CASE("a rational trivariate is the quotient of its homogeneous polynomials, mixed partials included") {
  // Numerator polynomials (w x, w y, w z, w r) and a positive weight polynomial, both blossomed
  // on the same knots: the rational spline with points num/w and weights w equals num / w.
  const std::array<KnotVector, 3> knots{test_knots(3, 21), test_knots(3, 22), test_knots(4, 23)};
  const auto num = TensorPoly<3>::random({2, 2, 3}, 4, 31);
  auto den = TensorPoly<3>::random({1, 1, 1}, 1, 32);
  for (double& a : den.A) a = 0.1 * std::abs(a);
  den.A[0] = 2.0;  // 2 + small positive terms on [0,1]^3: positive coefficients
  const auto N = num.spline(knots);
  const auto D = den.spline(knots);
  std::vector<double> pts(N.points().begin(), N.points().end()), w(D.points().begin(), D.points().end());
  for (int r = 0; r < N.size(); ++r) {
    REQUIRE(w[static_cast<std::size_t>(r)] > 0);
    for (int h = 0; h < 4; ++h) pts[static_cast<std::size_t>(r * 4 + h)] /= w[static_cast<std::size_t>(r)];
  }
  const Trivariate R(knots, 4, pts, w);
  const auto alphas = derivative_multi_indices<3>(2);
  double worst = 0;
  for (const auto& t : trivox::test::random_params(R, 200, 5)) {
    const auto v = R.eval_derivatives(t, 2);
    // Exact derivatives of q = n / d by the quotient rule on the exact polynomials.
    const double d0 = den.value(t, 0);
    for (int h = 0; h < 4; ++h) {
      auto nd = [&](std::array<int, 3> a) { return num.derivative(t, a, h); };
      auto dd = [&](std::array<int, 3> a) { return den.derivative(t, a, 0); };
      const double q = nd({0, 0, 0}) / d0;
      std::array<double, 3> q1{};
      for (int i = 0; i < 3; ++i) {
        std::array<int, 3> e{};
        e[static_cast<std::size_t>(i)] = 1;
        q1[static_cast<std::size_t>(i)] = (nd(e) - dd(e) * q) / d0;
      }
      for (std::size_t k = 0; k < alphas.size(); ++k) {
        const auto& a = alphas[k];
        double exact;
        const int order = a[0] + a[1] + a[2];
        if (order == 0) exact = q;
        else if (order == 1) exact = q1[static_cast<std::size_t>(a[0] ? 0 : a[1] ? 1 : 2)];
        else {
          // d_ij q = (d_ij n - d_ij d q - d_i d d_j q - d_j d d_i q) / d
          int i = -1, j = -1;
          for (int e = 0; e < 3; ++e)
            for (int r = 0; r < a[static_cast<std::size_t>(e)]; ++r) (i < 0 ? i : j) = e;
          std::array<int, 3> ei{}, ej{};
          ei[static_cast<std::size_t>(i)] = 1;
          ej[static_cast<std::size_t>(j)] = 1;
          exact = (nd(a) - dd(a) * q - dd(ei) * q1[static_cast<std::size_t>(j)] - dd(ej) * q1[static_cast<std::size_t>(i)]) / d0;
        }
        worst = std::max(worst, std::abs(v[k * 4 + static_cast<std::size_t>(h)] - exact) / (1 + std::abs(exact)));
      }
    }
  }
  INFO("worst relative deviation " << worst);
  CHECK(worst < 1e-11);
}

TEST_CASE("control points and weights are validated") {
  const KnotVector kv = KnotVector::bezier(2);
  CHECK_THROWS_WITH(Curve({kv}, 2, {0, 0, 1}), Catch::Contains("expected 2 control points x 2 coordinates"));
  CHECK_THROWS_WITH(Curve({kv}, 1, {0, std::nan("")}), Catch::Contains("finite"));
  CHECK_THROWS_WITH(Curve({kv}, 1, {0, 1}, {1.0}), Catch::Contains("one per control point"));
  CHECK_THROWS_WITH(Curve({kv}, 1, {0, 1}, {1.0, -2.0}), Catch::Contains("positive"));
  CHECK_THROWS_WITH(Curve({kv}, 0, {}), Catch::Contains("at least 1"));
}

TEST_CASE("the coherent Evaluator equals plain evaluation on scanlines and random points") {
  const std::array<KnotVector, 3> knots{test_knots(4, 41), test_knots(3, 42), test_knots(4, 43)};
  const auto f = TensorPoly<3>::random({3, 2, 3}, 6, 44);
  const auto s = f.spline(knots);
  Evaluator<3> ev(s);
  std::vector<double> a(24), b(24);
  double worst = 0;
  auto compare = [&](const std::array<double, 3>& t) {
    ev.eval_first(t, a.data());
    s.eval_derivatives(t, 1, b.data());
    for (int i = 0; i < 24; ++i) worst = std::max(worst, std::abs(a[static_cast<std::size_t>(i)] - b[static_cast<std::size_t>(i)]) / (1 + std::abs(b[static_cast<std::size_t>(i)])));
    ev.eval(t, a.data());
    for (int i = 0; i < 6; ++i) worst = std::max(worst, std::abs(a[static_cast<std::size_t>(i)] - b[static_cast<std::size_t>(i)]) / (1 + std::abs(b[static_cast<std::size_t>(i)])));
  };
  for (int k = 0; k < 7; ++k)
    for (int j = 0; j < 9; ++j)
      for (int i = 0; i <= 40; ++i) compare({i / 40.0, j / 8.0, k / 6.0});
  for (const auto& t : trivox::test::random_params(s, 500, 3)) compare(t);
  CHECK(worst < 1e-13);

  // Surfaces too.
  const auto g = TensorPoly<2>::random({2, 3}, 3, 45);
  const auto surf = g.spline({test_knots(3, 46), test_knots(4, 47)});
  Evaluator<2> es(surf);
  double w2 = 0;
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i <= 30; ++i) {
      const std::array<double, 2> t{i / 30.0, j / 4.0};
      std::vector<double> x(9), y(9);
      es.eval_first(t, x.data());
      surf.eval_derivatives(t, 1, y.data());
      for (int h = 0; h < 9; ++h) w2 = std::max(w2, std::abs(x[static_cast<std::size_t>(h)] - y[static_cast<std::size_t>(h)]));
    }
  CHECK(w2 < 1e-13);
}

TEST_CASE("batch evaluation equals point evaluation and checks its sizes") {
  const auto f = TensorPoly<3>::random({3, 3, 2}, 4, 51);
  const auto s = f.spline({test_knots(4, 52), test_knots(4, 53), test_knots(3, 54)});
  const auto ts = trivox::test::random_params(s, 5000, 55);
  std::vector<double> params;
  for (const auto& t : ts) params.insert(params.end(), t.begin(), t.end());
  std::vector<double> out(ts.size() * 4);
  s.eval_many(params, out);
  for (std::size_t i = 0; i < ts.size(); ++i) {
    const auto v = s.eval(ts[i]);
    for (std::size_t h = 0; h < 4; ++h) REQUIRE(out[i * 4 + h] == v[h]);  // same arithmetic, bit for bit
  }
  std::vector<double> wrong(7);
  CHECK_THROWS_WITH(s.eval_many(params, wrong), Catch::Contains("expected n x 3"));
}
