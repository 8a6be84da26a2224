#include "trivox/geom/quadrature.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "trivox/error.hpp"
#include "trivox/limits.hpp"
#include "trivox/spline/evaluator.hpp"

namespace trivox::geom {

GaussRule gauss_legendre(int n) {
  // Time O(n^2), memory O(n); callers bound n by the orders they accept (trivox/limits.hpp).
  if (n < 1 || n > 4096) throw Error("Gauss rule of " + std::to_string(n) + " points; expected 1..4096");
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
/// value and first partials (4 x dim values). The points are evaluated line by line (fixed v and
/// w, all of a row of elements along u: spline::Evaluator's cached lines, several times faster
/// than evaluating each point alone on the thousand-span cells of fillets), rows of elements in
/// parallel; each element's sum runs over its points in the fixed order (w, v, u nodes) and the
/// elements are added in the fixed order (w, v, u), so the result does not depend on the threads.
template <class F>
double integrate(const spline::Trivariate& s, int extra_points, F&& f) {
  if (s.dim() < 3) throw Error("integral over a trivariate in R^" + std::to_string(s.dim()) + "; expected xyz");
  // Before any rule is built: the points per direction grow with the order, the work with its cube.
  const Limits limits = default_limits();
  for (int d = 0; d < 3; ++d)
    check_order(s.knots(d).order(), limits, std::string("integral over a cell, direction ") + "uvw"[d]);
  std::array<GaussRule, 3> rules;
  std::array<std::vector<double>, 3> breaks;
  for (int d = 0; d < 3; ++d) {
    const int p = s.knots(d).degree();
    const int n = s.rational() ? 3 * p + 2 + extra_points : std::max(1, (3 * p + 1) / 2 + extra_points);
    rules[static_cast<std::size_t>(d)] = gauss_legendre(n);
    for (const auto& b : s.knots(d).breakpoints()) breaks[static_cast<std::size_t>(d)].push_back(b.value);
  }
  const std::size_t nu = breaks[0].size() - 1, nv = breaks[1].size() - 1, nw = breaks[2].size() - 1;
  const std::size_t dim = static_cast<std::size_t>(s.dim());
  // The element sums, row (ev, ew) after row, elements along u within a row.
  std::vector<double> element(nu * nv * nw, 0.0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nv * nw), [&](const tbb::blocked_range<std::size_t>& rows) {
    spline::Evaluator<3> ev(s);
    std::vector<double> v(4 * dim);
    for (std::size_t row = rows.begin(); row != rows.end(); ++row) {
      const std::size_t e_v = row % nv, e_w = row / nv;
      double* acc = element.data() + row * nu;
      const double lo_v = breaks[1][e_v], half_v = 0.5 * (breaks[1][e_v + 1] - lo_v);
      const double lo_w = breaks[2][e_w], half_w = 0.5 * (breaks[2][e_w + 1] - lo_w);
      for (std::size_t k = 0; k < rules[2].nodes.size(); ++k)
        for (std::size_t j = 0; j < rules[1].nodes.size(); ++j)
          for (std::size_t eu = 0; eu < nu; ++eu) {
            const double lo_u = breaks[0][eu], half_u = 0.5 * (breaks[0][eu + 1] - lo_u);
            for (std::size_t i = 0; i < rules[0].nodes.size(); ++i) {
              const std::array<double, 3> t{lo_u + half_u * (1 + rules[0].nodes[i]), lo_v + half_v * (1 + rules[1].nodes[j]),
                                            lo_w + half_w * (1 + rules[2].nodes[k])};
              ev.eval_first(t, v.data());
              const double* du = &v[dim];
              const double* dv = du + dim;
              const double* dw = dv + dim;
              const double det = du[0] * (dv[1] * dw[2] - dv[2] * dw[1]) - du[1] * (dv[0] * dw[2] - dv[2] * dw[0]) +
                                 du[2] * (dv[0] * dw[1] - dv[1] * dw[0]);
              acc[eu] += rules[0].weights[i] * rules[1].weights[j] * rules[2].weights[k] * f(v.data(), det);
            }
          }
    }
  });
  double total = 0.0;
  for (std::size_t e_w = 0; e_w < nw; ++e_w)
    for (std::size_t e_v = 0; e_v < nv; ++e_v)
      for (std::size_t eu = 0; eu < nu; ++eu) {
        const double half[3] = {0.5 * (breaks[0][eu + 1] - breaks[0][eu]), 0.5 * (breaks[1][e_v + 1] - breaks[1][e_v]),
                                0.5 * (breaks[2][e_w + 1] - breaks[2][e_w])};
        total += element[(e_w * nv + e_v) * nu + eu] * half[0] * half[1] * half[2];
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
