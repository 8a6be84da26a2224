// Gauss-Legendre rules and volumes from the Jacobian determinant, against analytic values.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "trivox/geom/quadrature.hpp"
#include "trivox/spline/refine.hpp"

using namespace trivox;
using spline::KnotVector;
using spline::Trivariate;

TEST_CASE("an n-point Gauss-Legendre rule integrates x^k exactly for k <= 2n - 1") {
  for (int n = 1; n <= 20; ++n) {
    const auto g = geom::gauss_legendre(n);
    for (int k = 0; k <= 2 * n - 1; ++k) {
      double s = 0;
      for (int i = 0; i < n; ++i) s += g.weights[static_cast<std::size_t>(i)] * std::pow(g.nodes[static_cast<std::size_t>(i)], k);
      const double exact = (k % 2) ? 0.0 : 2.0 / (k + 1);
      CHECK(s == Approx(exact).margin(1e-14));
    }
  }
  CHECK_THROWS(geom::gauss_legendre(0));
}

namespace {
/// The trilinear cell interpolating f at the 8 corners of [0,1]^3 (exact for multilinear f).
template <class F>
Trivariate trilinear(F&& f, int dim = 3) {
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        const auto p = f(double(i), double(j), double(k));
        pts.insert(pts.end(), p.begin(), p.begin() + dim);
      }
  const KnotVector lin = KnotVector::bezier(2);
  return Trivariate({lin, lin, lin}, dim, pts);
}
}  // namespace

TEST_CASE("volumes of polynomial cells are exact") {
  // A box 2 x 3 x 5.
  const auto box = trilinear([](double u, double v, double w) { return std::vector<double>{2 * u, 3 * v, 5 * w}; });
  CHECK(geom::volume(box) == Approx(30.0).epsilon(1e-14));
  // z = w (1 + u v): volume = int_0^1 int_0^1 (1 + u v) du dv = 5/4.
  const auto warped = trilinear([](double u, double v, double w) { return std::vector<double>{u, v, w * (1 + u * v)}; });
  CHECK(geom::volume(warped) == Approx(1.25).epsilon(1e-14));
  // Refining and elevating changes nothing; reversing a direction flips the sign only.
  const auto fine = spline::elevate(spline::refine_uniform(warped, 1, 3), 2, 2);
  CHECK(geom::volume(fine) == Approx(1.25).epsilon(1e-13));
  CHECK(geom::signed_volume(spline::reverse(warped, 0)) == Approx(-1.25).epsilon(1e-14));
  // A property integrates to its mean times the volume: r = u on the unit cube gives 1/2.
  const auto graded = trilinear([](double u, double v, double w) { return std::vector<double>{u, v, w, u}; }, 4);
  CHECK(geom::integrate_coordinate(graded, 3) == Approx(0.5).epsilon(1e-14));
}

TEST_CASE("the volume of a rational quarter-annulus slab is close to 9 pi / 4") {
  // u: the rational quadratic quarter circle; v: radius 1 to 2; w: height 0 to 3.
  const double c = std::sqrt(0.5);
  const double arc[3][2] = {{1, 0}, {1, 1}, {0, 1}};
  const double wts[3] = {1, c, 1};
  std::vector<double> pts, w;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i) {
        const double r = 1.0 + j;
        pts.insert(pts.end(), {r * arc[i][0], r * arc[i][1], 3.0 * k});
        w.push_back(wts[i]);
      }
  const Trivariate slab({KnotVector::bezier(3), KnotVector::bezier(2), KnotVector::bezier(2)}, 3, pts, w);
  CHECK(geom::volume(slab) == Approx(9.0 * std::numbers::pi / 4.0).epsilon(1e-9));
}
