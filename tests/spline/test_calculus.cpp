// Derivative splines equal the evaluated partials; product splines equal pointwise products; the
// Jacobian determinant spline equals det(J) and integrates to analytic volumes.
#include <catch2/catch.hpp>

#include <cmath>

#include "poly.hpp"
#include "trivox/error.hpp"
#include "trivox/spline/calculus.hpp"
#include "trivox/spline/refine.hpp"

using namespace trivox::spline;
using trivox::test::random_params;
using trivox::test::TensorPoly;
using trivox::test::test_knots;

namespace {
Trivariate random_poly_trivariate(int dim, unsigned seed) {
  const auto f = TensorPoly<3>::random({3, 2, 3}, dim, seed);
  return f.spline({test_knots(4, seed + 1), test_knots(3, seed + 2), test_knots(4, seed + 3)});
}
Trivariate random_net(int dim, unsigned seed, std::array<KnotVector, 3> knots) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  int n = 1;
  for (const auto& k : knots) n *= k.size();
  std::vector<double> pts(static_cast<std::size_t>(n * dim));
  for (double& p : pts) p = U(rng);
  return Trivariate(knots, dim, std::move(pts));
}
}  // namespace

TEST_CASE("derivative splines equal the partial derivatives, exactly as splines") {
  // A general spline (random net, a double knot): compare with the evaluated partials.
  const Trivariate s = random_net(4, 1, {test_knots(4, 2), test_knots(3, 3), test_knots(2, 4, 0, 1, 3)});
  for (int d = 0; d < 3; ++d) {
    const Trivariate ds = derivative(s, d);
    CHECK(ds.knots(d).order() == s.knots(d).order() - 1);
    std::array<int, 3> alpha{};
    alpha[static_cast<std::size_t>(d)] = 1;
    const int slot = derivative_slot<3>(alpha);
    double worst = 0;
    for (const auto& t : random_params(s, 300, 5)) {
      const auto v = s.eval_derivatives(t, 1);
      const auto w = ds.eval(t);
      for (int h = 0; h < 4; ++h)
        worst = std::max(worst, std::abs(w[static_cast<std::size_t>(h)] - v[static_cast<std::size_t>(slot * 4 + h)]) /
                                    (1 + std::abs(w[static_cast<std::size_t>(h)])));
    }
    INFO("direction " << d);
    CHECK(worst < 1e-12);
  }
  // A C^-1 knot (multiplicity = order): the derivative drops the dead basis function.
  const Curve c({KnotVector(3, {0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1})}, 1, {0, 1, 4, -1, 2, 0});
  const Curve dc = derivative(c, 0);
  CHECK(dc.knots(0).multiplicity(0.5) == 2);
  CHECK(dc.eval({0.25})[0] == Approx(c.eval_derivatives({0.25}, 1)[1]));
  CHECK(dc.eval({0.75})[0] == Approx(c.eval_derivatives({0.75}, 1)[1]));
  CHECK_THROWS_WITH(derivative(Curve({KnotVector::bezier(1)}, 1, {2.0}), 0), Catch::Contains("order >= 2"));
  CHECK_THROWS_WITH(derivative(Curve({KnotVector::bezier(2)}, 1, {0, 1}, {1, 2}), 0), Catch::Contains("polynomial"));
}

TEST_CASE("products of splines equal pointwise products") {
  const Trivariate a = random_poly_trivariate(3, 10);
  const Trivariate b = random_net(3, 11, {test_knots(2, 12), test_knots(4, 13), test_knots(3, 14)});
  const Trivariate sa = coordinates(a, 0, 1), sb = coordinates(b, 1, 1);
  struct Case {
    ProductKind kind;
    const Trivariate* x;
    const Trivariate* y;
  };
  const Case cases[] = {{ProductKind::scalar, &sa, &sb},
                        {ProductKind::scalar_vector, &sa, &b},
                        {ProductKind::dot, &a, &b},
                        {ProductKind::cross, &a, &b},
                        {ProductKind::componentwise, &a, &b}};
  for (const auto& c : cases) {
    const Trivariate p = product(*c.x, *c.y, c.kind);
    for (int d = 0; d < 3; ++d) CHECK(p.knots(d).order() == c.x->knots(d).order() + c.y->knots(d).order() - 1);
    double worst = 0;
    for (const auto& t : random_params(p, 300, 6)) {
      const auto x = c.x->eval(t), y = c.y->eval(t), v = p.eval(t);
      std::vector<double> e;
      switch (c.kind) {
        case ProductKind::scalar: e = {x[0] * y[0]}; break;
        case ProductKind::scalar_vector: e = {x[0] * y[0], x[0] * y[1], x[0] * y[2]}; break;
        case ProductKind::dot: e = {x[0] * y[0] + x[1] * y[1] + x[2] * y[2]}; break;
        case ProductKind::cross: e = {x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]}; break;
        case ProductKind::componentwise: e = {x[0] * y[0], x[1] * y[1], x[2] * y[2]}; break;
      }
      REQUIRE(e.size() == v.size());
      for (std::size_t h = 0; h < e.size(); ++h) worst = std::max(worst, std::abs(v[h] - e[h]) / (1 + std::abs(e[h])));
    }
    INFO("product kind " << static_cast<int>(c.kind));
    CHECK(worst < 1e-12);
  }
  CHECK_THROWS_WITH(product(a, b, ProductKind::scalar), Catch::Contains("expected scalar*scalar"));
  const Trivariate other = reparametrize(b, 0, 0.0, 2.0);
  CHECK_THROWS_WITH(product(a, other, ProductKind::dot), Catch::Contains("different domains"));
}

TEST_CASE("sums of splines in different spaces") {
  const Trivariate a = random_poly_trivariate(2, 20);
  const Trivariate b = random_net(2, 21, {test_knots(2, 22), test_knots(4, 23), test_knots(3, 24)});
  const Trivariate s = add(a, b, -0.5);
  double worst = 0;
  for (const auto& t : random_params(s, 200, 7))
    for (int h = 0; h < 2; ++h)
      worst = std::max(worst, std::abs(s.eval(t)[static_cast<std::size_t>(h)] -
                                       (a.eval(t)[static_cast<std::size_t>(h)] - 0.5 * b.eval(t)[static_cast<std::size_t>(h)])));
  CHECK(worst < 1e-12);
}

TEST_CASE("the Jacobian determinant spline equals det of the evaluated Jacobian") {
  // A curved trivariate with properties: a perturbed unit cube.
  const auto f = TensorPoly<3>::random({2, 2, 2}, 4, 30);
  Trivariate s = f.spline({test_knots(3, 31), test_knots(3, 32), test_knots(3, 33)});
  // Make xyz close to the identity map so the determinant is positive.
  for (int r = 0; r < s.size(); ++r) {
    auto p = s.point(r);
    const auto g = s.multi_index(r);
    for (int d = 0; d < 3; ++d)
      p[static_cast<std::size_t>(d)] = s.knots(d).greville()[static_cast<std::size_t>(g[static_cast<std::size_t>(d)])] + 0.05 * p[static_cast<std::size_t>(d)];
  }
  const Trivariate J = jacobian_determinant(s);
  CHECK(J.dim() == 1);
  double worst = 0;
  for (const auto& t : random_params(s, 300, 8)) {
    const auto v = s.eval_derivatives(t, 1);
    const double* du = &v[4];
    const double* dv = &v[8];
    const double* dw = &v[12];
    const double det = du[0] * (dv[1] * dw[2] - dv[2] * dw[1]) - du[1] * (dv[0] * dw[2] - dv[2] * dw[0]) +
                       du[2] * (dv[0] * dw[1] - dv[1] * dw[0]);
    worst = std::max(worst, std::abs(J.eval(t)[0] - det));
  }
  CHECK(worst < 1e-11);

  // The box [0,a] x [0,b] x [0,c] as a trilinear map has det = abc everywhere: all coefficients.
  const KnotVector lin = KnotVector::bezier(2);
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) pts.insert(pts.end(), {2.0 * i, 3.0 * j, 5.0 * k});
  const Trivariate box({lin, lin, lin}, 3, pts);
  const Trivariate Jbox = jacobian_determinant(box);
  for (double c : Jbox.points()) CHECK(c == Approx(30.0).epsilon(1e-13));

  // A planar surface: the unit disk quadrant in polar-like form is rational, so use a bilinear
  // quad (0,0) (2,0) (0,1) (3,2): det is linear, equal to the cross product of the partials.
  const Surface quad({lin, lin}, 2, {0, 0, 2, 0, 0, 1, 3, 2});
  const Surface Jq = jacobian_determinant(quad);
  for (double u : {0.0, 0.3, 1.0})
    for (double v : {0.0, 0.6, 1.0}) {
      const auto d = quad.eval_derivatives({u, v}, 1);
      CHECK(Jq.eval({u, v})[0] == Approx(d[2] * d[5] - d[3] * d[4]).margin(1e-13));
    }
}
