// Test truths for the spline kernel: tensor-product polynomials with random coefficients, and
// their exact B-spline representation by blossoming.
//
// A polynomial of degree <= p in one variable, f(x) = sum_k a_k x^k, has the B-spline
// coefficients c_i = sum_k a_k e_k(t_{i+1}, .., t_{i+p}) / C(p, k) on any knot vector of degree p
// (the blossom of x^k is the normalised elementary symmetric polynomial; de Boor-Fix / Ramshaw).
// Tensor products blossom direction by direction. Values and derivatives of the polynomial are
// computed from the monomial coefficients, independently of the B-spline code.
#pragma once
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::test {

using spline::KnotVector;
using spline::TensorSpline;

/// e_k(x_1..x_m) / C(m, k).
inline double normalised_elementary(const double* x, int m, int k) {
  // e_j by the recurrence over the variables.
  std::vector<double> e(static_cast<std::size_t>(m + 1), 0.0);
  e[0] = 1.0;
  for (int i = 0; i < m; ++i)
    for (int j = i + 1; j >= 1; --j) e[static_cast<std::size_t>(j)] += x[i] * e[static_cast<std::size_t>(j - 1)];
  double c = 1.0;
  for (int i = 1; i <= k; ++i) c = c * (m - k + i) / i;
  return e[static_cast<std::size_t>(k)] / c;
}

/// Blossom coefficients of monomial x^k on knot vector kv: one value per basis function.
inline std::vector<double> monomial_coefficients(const KnotVector& kv, int k) {
  const int p = kv.degree();
  std::vector<double> c(static_cast<std::size_t>(kv.size()));
  for (int i = 0; i < kv.size(); ++i) c[static_cast<std::size_t>(i)] = normalised_elementary(&kv.knots()[static_cast<std::size_t>(i + 1)], p, k);
  return c;
}

/// f_h(t) = sum over multi-indices a (a_d <= deg_d) of A[h][a] prod_d t_d^{a_d}.
template <int P>
struct TensorPoly {
  std::array<int, P> deg{};
  int dim = 1;
  std::vector<double> A;  // dim x prod(deg+1), first exponent fastest

  int terms() const {
    int n = 1;
    for (int d = 0; d < P; ++d) n *= deg[static_cast<std::size_t>(d)] + 1;
    return n;
  }
  std::array<int, P> exponents(int term) const {
    std::array<int, P> a{};
    for (int d = 0; d < P; ++d) {
      a[static_cast<std::size_t>(d)] = term % (deg[static_cast<std::size_t>(d)] + 1);
      term /= deg[static_cast<std::size_t>(d)] + 1;
    }
    return a;
  }

  static TensorPoly random(std::array<int, P> deg, int dim, unsigned seed) {
    TensorPoly f;
    f.deg = deg;
    f.dim = dim;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    f.A.resize(static_cast<std::size_t>(dim * f.terms()));
    for (double& a : f.A) a = U(rng);
    return f;
  }

  /// The partial derivative of multi-index alpha at t, coordinate h.
  double derivative(const std::array<double, P>& t, const std::array<int, P>& alpha, int h) const {
    double sum = 0.0;
    for (int term = 0; term < terms(); ++term) {
      const auto a = exponents(term);
      double m = A[static_cast<std::size_t>(h * terms() + term)];
      for (int d = 0; d < P; ++d) {
        const auto dd = static_cast<std::size_t>(d);
        if (a[dd] < alpha[dd]) { m = 0.0; break; }
        for (int r = 0; r < alpha[dd]; ++r) m *= (a[dd] - r);
        m *= std::pow(t[dd], a[dd] - alpha[dd]);
      }
      sum += m;
    }
    return sum;
  }
  double value(const std::array<double, P>& t, int h) const { return derivative(t, std::array<int, P>{}, h); }

  /// The exact B-spline representation on the given knots (degree of each >= deg).
  TensorSpline<P> spline(const std::array<KnotVector, P>& knots) const {
    std::array<std::vector<std::vector<double>>, P> mono;  // [d][k][i]
    int n = 1;
    for (int d = 0; d < P; ++d) {
      const auto dd = static_cast<std::size_t>(d);
      for (int k = 0; k <= deg[dd]; ++k) mono[dd].push_back(monomial_coefficients(knots[dd], k));
      n *= knots[dd].size();
    }
    std::vector<double> pts(static_cast<std::size_t>(n * dim), 0.0);
    for (int r = 0; r < n; ++r) {
      std::array<int, P> idx{};
      int q = r;
      for (int d = 0; d < P; ++d) {
        idx[static_cast<std::size_t>(d)] = q % knots[static_cast<std::size_t>(d)].size();
        q /= knots[static_cast<std::size_t>(d)].size();
      }
      for (int term = 0; term < terms(); ++term) {
        const auto a = exponents(term);
        double c = 1.0;
        for (int d = 0; d < P; ++d)
          c *= mono[static_cast<std::size_t>(d)][static_cast<std::size_t>(a[static_cast<std::size_t>(d)])][static_cast<std::size_t>(idx[static_cast<std::size_t>(d)])];
        for (int h = 0; h < dim; ++h) pts[static_cast<std::size_t>(r * dim + h)] += c * A[static_cast<std::size_t>(h * terms() + term)];
      }
    }
    return TensorSpline<P>(knots, dim, std::move(pts));
  }
};

/// A non-uniform clamped knot vector on [a, b] with one double interior knot (order > 2).
inline KnotVector test_knots(int order, unsigned seed, double a = 0.0, double b = 1.0, int interior = 4) {
  // Jittered uniform interior knots: non-uniform, but no two closer than 0.4 of the mean gap, so
  // the derivatives' rounding errors stay at the scale the tolerances assume.
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-0.3, 0.3);
  std::vector<double> k(static_cast<std::size_t>(order), a);
  std::vector<double> in;
  for (int i = 0; i < interior; ++i) in.push_back(a + (b - a) * (i + 1 + U(rng)) / (interior + 1));
  for (std::size_t i = 0; i < in.size(); ++i) {
    k.push_back(in[i]);
    if (i == 1 && order > 2) k.push_back(in[i]);  // one double knot
  }
  for (int i = 0; i < order; ++i) k.push_back(b);
  return KnotVector(order, std::move(k));
}

/// Uniformly random parameters inside the spline's domain.
template <int P>
std::vector<std::array<double, P>> random_params(const TensorSpline<P>& s, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<std::array<double, P>> out(static_cast<std::size_t>(n));
  for (auto& t : out)
    for (int d = 0; d < P; ++d) {
      std::uniform_real_distribution<double> U(s.domain(d)[0], s.domain(d)[1]);
      t[static_cast<std::size_t>(d)] = U(rng);
    }
  // Include the domain corners.
  for (int c = 0; c < (1 << P) && c < n; ++c)
    for (int d = 0; d < P; ++d) out[static_cast<std::size_t>(c)][static_cast<std::size_t>(d)] = s.domain(d)[(c >> d) & 1];
  return out;
}

/// max |a(t) - b(t)| over the parameters, over all coordinates.
template <int P, class F>
double max_deviation(const TensorSpline<P>& s, const std::vector<std::array<double, P>>& ts, F&& truth) {
  double worst = 0.0;
  for (const auto& t : ts) {
    const auto v = s.eval(t);
    for (int h = 0; h < s.dim(); ++h) worst = std::max(worst, std::abs(v[static_cast<std::size_t>(h)] - truth(t, h)));
  }
  return worst;
}

}  // namespace trivox::test
