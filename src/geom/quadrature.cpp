#include "trivox/geom/quadrature.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "trivox/error.hpp"

namespace trivox::geom {

GaussRule gauss_legendre(int n) {
  if (n < 1 || n > 64) throw Error("Gauss rule of " + std::to_string(n) + " points; expected 1..64");
  // Newton's method on the Legendre polynomial from Chebyshev-like starts (Numerical Recipes
  // gauleg); the three-term recurrence gives P_n and P_n'.
  GaussRule g{std::vector<double>(static_cast<std::size_t>(n)), std::vector<double>(static_cast<std::size_t>(n))};
  for (int i = 0; i < (n + 1) / 2; ++i) {
    double x = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
    double dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = 0.0;
      for (int j = 1; j <= n; ++j) {
        const double p2 = p1;
        p1 = p0;
        p0 = ((2.0 * j - 1.0) * x * p1 - (j - 1.0) * p2) / j;
      }
      dp = n * (x * p0 - p1) / (x * x - 1.0);
      const double dx = p0 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    const double w = 2.0 / ((1.0 - x * x) * dp * dp);
    g.nodes[static_cast<std::size_t>(i)] = -x;
    g.nodes[static_cast<std::size_t>(n - 1 - i)] = x;
    g.weights[static_cast<std::size_t>(i)] = w;
    g.weights[static_cast<std::size_t>(n - 1 - i)] = w;
  }
  return g;
}

namespace {

/// Sum over Bezier elements and Gauss points of weight * f(t, J, value), f given the point's
/// value and first partials (4 x dim values).
template <class F>
double integrate(const spline::Trivariate& s, int extra_points, F&& f) {
  if (s.dim() < 3) throw Error("integral over a trivariate in R^" + std::to_string(s.dim()) + "; expected xyz");
  std::array<GaussRule, 3> rules;
  std::array<std::vector<double>, 3> breaks;
  for (int d = 0; d < 3; ++d) {
    const int p = s.knots(d).degree();
    const int n = s.rational() ? 3 * p + 2 + extra_points : std::max(1, (3 * p + 1) / 2 + extra_points);
    rules[static_cast<std::size_t>(d)] = gauss_legendre(n);
    for (const auto& b : s.knots(d).breakpoints()) breaks[static_cast<std::size_t>(d)].push_back(b.value);
  }
  std::vector<double> v(static_cast<std::size_t>(4 * s.dim()));
  double total = 0.0;
  for (std::size_t ew = 0; ew + 1 < breaks[2].size(); ++ew)
    for (std::size_t ev = 0; ev + 1 < breaks[1].size(); ++ev)
      for (std::size_t eu = 0; eu + 1 < breaks[0].size(); ++eu) {
        const std::size_t e[3] = {eu, ev, ew};
        double lo[3], half[3];
        for (int d = 0; d < 3; ++d) {
          lo[d] = breaks[static_cast<std::size_t>(d)][e[d]];
          half[d] = 0.5 * (breaks[static_cast<std::size_t>(d)][e[d] + 1] - lo[d]);
        }
        double element = 0.0;
        for (std::size_t k = 0; k < rules[2].nodes.size(); ++k)
          for (std::size_t j = 0; j < rules[1].nodes.size(); ++j)
            for (std::size_t i = 0; i < rules[0].nodes.size(); ++i) {
              const std::array<double, 3> t{lo[0] + half[0] * (1 + rules[0].nodes[i]), lo[1] + half[1] * (1 + rules[1].nodes[j]),
                                            lo[2] + half[2] * (1 + rules[2].nodes[k])};
              s.eval_derivatives(t, 1, v.data());
              const double* du = &v[static_cast<std::size_t>(s.dim())];
              const double* dv = du + s.dim();
              const double* dw = dv + s.dim();
              const double det = du[0] * (dv[1] * dw[2] - dv[2] * dw[1]) - du[1] * (dv[0] * dw[2] - dv[2] * dw[0]) +
                                 du[2] * (dv[0] * dw[1] - dv[1] * dw[0]);
              element += rules[0].weights[i] * rules[1].weights[j] * rules[2].weights[k] * f(v.data(), det);
            }
        total += element * half[0] * half[1] * half[2];
      }
  return total;
}

}  // namespace

double signed_volume(const spline::Trivariate& cell) {
  return integrate(cell, 0, [](const double*, double det) { return det; });
}

double volume(const spline::Trivariate& cell) { return std::abs(signed_volume(cell)); }

double integrate_coordinate(const spline::Trivariate& cell, int coord) {
  if (coord < 0 || coord >= cell.dim())
    throw Error("coordinate " + std::to_string(coord) + "; expected 0.." + std::to_string(cell.dim() - 1));
  const double sign = signed_volume(cell) < 0 ? -1.0 : 1.0;
  // The property adds its degree p_d to the integrand: ceil(p_d / 2) more points suffice.
  int extra = 0;
  for (int d = 0; d < 3; ++d) extra = std::max(extra, (cell.knots(d).degree() + 1) / 2);
  return sign * integrate(cell, extra, [coord](const double* v, double det) { return v[coord] * det; });
}

}  // namespace trivox::geom
