/// @file trivox/spline/knot_vector.hpp
/// @brief A validated B-spline knot vector and its basis functions.
///
/// Conventions (as in IRIT, G+Smo and the papers): `order` = degree + 1; a knot vector of n basis
/// functions holds n + order non-decreasing knots t_0..t_{n+order-1}; the domain is
/// [t_{order-1}, t_n]. Interior knots may repeat up to `order` times (a discontinuity); end knots
/// may be clamped (repeated `order` times, so the spline interpolates its end control points) or
/// not. Basis evaluation is the Cox-de Boor triangle (Piegl & Tiller, The NURBS Book, A2.2/A2.3).
/// Cost: span search O(log n); basis values O(order^2); derivatives O(order^2 * nder).
#pragma once
#include <span>
#include <utility>
#include <vector>

namespace trivox::spline {

/// Largest derivative order the evaluators compute.
inline constexpr int max_derivative_order = 2;

/// One distinct knot value with its multiplicity.
struct Breakpoint {
  double value;
  int multiplicity;
};

class KnotVector {
public:
  KnotVector() = default;

  /// @param order  degree + 1, at least 1
  /// @param knots  n + order finite non-decreasing values, n >= order, non-empty domain,
  ///               no interior knot repeated more than `order` times
  /// @throws trivox::Error (bad_input) naming the first offending entry and what was expected,
  ///         or when its table of knot differences (spans x order x (order - 1) / 2 doubles,
  ///         built here) would exceed the process's default max_points (trivox/limits.hpp)
  /// Cost: O(spans x order^2) time and memory for that table.
  KnotVector(int order, std::vector<double> knots);

  /// A clamped knot vector on [a, b] with `segments` uniform intervals.
  static KnotVector uniform(int order, int segments, double a = 0.0, double b = 1.0);
  /// The Bezier knot vector on [a, b]: `order` copies of a, then of b.
  static KnotVector bezier(int order, double a = 0.0, double b = 1.0);
  /// A clamped knot vector with the given breakpoints (first and last get multiplicity `order`,
  /// interior ones the given multiplicity).
  static KnotVector from_breakpoints(int order, std::span<const Breakpoint> breaks);

  int order() const noexcept { return order_; }
  int degree() const noexcept { return order_ - 1; }
  /// Number of basis functions (control points along this direction).
  int size() const noexcept { return static_cast<int>(knots_.size()) - order_; }
  const std::vector<double>& knots() const noexcept { return knots_; }
  double operator[](int i) const noexcept { return knots_[static_cast<std::size_t>(i)]; }

  /// The parametric domain [t_{order-1}, t_n].
  double front() const noexcept { return knots_[static_cast<std::size_t>(order_ - 1)]; }
  double back() const noexcept { return knots_[static_cast<std::size_t>(size())]; }
  bool contains(double t) const noexcept { return t >= front() && t <= back(); }

  /// True when the first and last `order` knots are equal (the curve interpolates its ends).
  bool clamped() const noexcept;

  /// The distinct knot values inside the domain (ends included), with multiplicities counted
  /// over the whole vector.
  std::vector<Breakpoint> breakpoints() const;
  /// Multiplicity of value `t` among the knots (0 when absent).
  int multiplicity(double t) const noexcept;

  /// The span index mu with t_mu <= t < t_{mu+1} and order-1 <= mu <= n-1; at the right end of
  /// the domain, the last non-empty span. `t` outside the domain is clamped to it.
  int find_span(double t) const noexcept;
  /// As find_span, but tries `hint` (a previous answer) first: O(1) for coherent parameters.
  int find_span(double t, int hint) const noexcept;

  /// The `order` basis functions non-zero on span `span`, at t: N_{span-order+1..span}(t).
  /// @param out  order values
  void basis(int span, double t, double* out) const noexcept;
  /// Values and derivatives up to `nder` (0..max_derivative_order) of those basis functions.
  /// @param out  (nder + 1) x order values, row r holding the r-th derivatives
  void basis_derivatives(int span, double t, int nder, double* out) const noexcept;

  /// Greville abscissae: the averages of the knots t_{i+1}..t_{i+order-1}, one per function.
  std::vector<double> greville() const;

  bool operator==(const KnotVector& o) const noexcept { return order_ == o.order_ && knots_ == o.knots_; }

private:
  const double* span_reciprocals(int span) const noexcept {
    const std::ptrdiff_t p = order_ - 1;
    return inv_.data() + (span - p) * (p * (p + 1) / 2);
  }

  int order_ = 0;
  std::vector<double> knots_;
  /// Per non-empty span mu: 1 / (t_{mu+r+1} - t_{mu+1-j+r}) for j = 1..degree, r < j, the
  /// denominators of Cox-de Boor, which do not depend on the parameter.
  std::vector<double> inv_;
};

}  // namespace trivox::spline
