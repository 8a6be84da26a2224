/// @file trivox/spline/tensor_spline.hpp
/// @brief Tensor-product B-spline curves (P = 1), surfaces (P = 2) and trivariates (P = 3) whose
/// control points live in R^k, k chosen at run time (xyz plus any number of properties).
///
/// Control point (i_0, .., i_{P-1}) is row i_0 + n_0 * (i_1 + n_1 * (i_2 ...)): the first
/// direction varies fastest, as in IRIT, G+Smo and the trivox model file. A spline with weights
/// is rational: its value is sum(w_i N_i P_i) / sum(w_i N_i) (the points are Cartesian, not
/// pre-multiplied by the weights).
///
/// Evaluation is the tensor contraction of the per-direction Cox-de Boor basis functions with
/// the order_0 x .. x order_{P-1} active control points. Cost per point: O(prod(order) * k).
/// For many parameters along scanlines use `Evaluator` (evaluator.hpp), which reuses spans and
/// partial contractions.
#pragma once
#include <array>
#include <span>
#include <vector>

#include "trivox/spline/knot_vector.hpp"

namespace trivox::spline {

/// Number of partial derivatives of total order <= `max_order` in P variables.
constexpr int derivative_count(int P, int max_order) {
  // C(P + max_order, P)
  int n = 1;
  for (int i = 1; i <= P; ++i) n = n * (max_order + i) / i;
  return n;
}

/// The multi-indices of all partial derivatives of total order <= 2 in P variables, in the order
/// the evaluators write them: by total order, then lexicographically with the first direction
/// highest. P = 3: 000, 100, 010, 001, 200, 110, 101, 020, 011, 002.
template <int P>
std::span<const std::array<int, P>> derivative_multi_indices(int max_order);

/// Position of multi-index `alpha` (total order <= 2) in that list.
template <int P>
int derivative_slot(const std::array<int, P>& alpha);

template <int P>
class TensorSpline {
  static_assert(P >= 1 && P <= 3, "trivox splines have 1, 2 or 3 parameters");

public:
  static constexpr int parameters = P;
  using Params = std::array<double, P>;
  using Index = std::array<int, P>;

  TensorSpline() = default;

  /// @param knots    one knot vector per direction
  /// @param dim      coordinates per control point (k >= 1)
  /// @param points   prod(knots[d].size()) * dim values, control point after control point
  /// @param weights  empty (polynomial) or one positive finite weight per control point
  /// @throws trivox::Error (bad_input) on a size mismatch or a non-finite value
  TensorSpline(std::array<KnotVector, P> knots, int dim, std::vector<double> points,
               std::vector<double> weights = {});

  int dim() const noexcept { return dim_; }
  const KnotVector& knots(int d) const noexcept { return knots_[static_cast<std::size_t>(d)]; }
  const std::array<KnotVector, P>& knot_vectors() const noexcept { return knots_; }
  int count(int d) const noexcept { return knots(d).size(); }
  Index counts() const noexcept;
  Index orders() const noexcept;
  /// Total number of control points.
  int size() const noexcept;
  bool rational() const noexcept { return !weights_.empty(); }

  /// All control points, `size() * dim()` values.
  std::span<const double> points() const noexcept { return points_; }
  std::span<double> points() noexcept { return points_; }
  std::span<const double> point(int row) const noexcept {
    return {points_.data() + static_cast<std::size_t>(row) * static_cast<std::size_t>(dim_),
            static_cast<std::size_t>(dim_)};
  }
  std::span<double> point(int row) noexcept {
    return {points_.data() + static_cast<std::size_t>(row) * static_cast<std::size_t>(dim_),
            static_cast<std::size_t>(dim_)};
  }
  /// Empty for a polynomial spline, else one weight per control point.
  const std::vector<double>& weights() const noexcept { return weights_; }
  std::vector<double>& weights() noexcept { return weights_; }

  /// Row of control point (i_0, .., i_{P-1}).
  int row(const Index& i) const noexcept;
  Index multi_index(int row) const noexcept;

  /// Domain [front, back] of direction d.
  std::array<double, 2> domain(int d) const noexcept { return {knots(d).front(), knots(d).back()}; }
  bool contains(const Params& t) const noexcept;

  /// The point at parameter t (clamped to the domain).
  /// @param out  dim() values
  void eval(const Params& t, double* out) const noexcept;
  std::vector<double> eval(const Params& t) const;

  /// The point and its partial derivatives of total order <= max_order (0..2) at t.
  /// @param out  derivative_count(P, max_order) x dim() values, in the order of
  ///             derivative_multi_indices (rational splines by the quotient rule)
  void eval_derivatives(const Params& t, int max_order, double* out) const noexcept;
  std::vector<double> eval_derivatives(const Params& t, int max_order) const;

  /// Points at many parameters, in parallel over chunks.
  /// @param params  n x P values; @param out  n x dim() values
  void eval_many(std::span<const double> params, std::span<double> out) const;

  /// Componentwise min and max of the control points: a bounding box of the spline (the convex
  /// hull property; also for positive weights). Returns {min(dim), max(dim)}.
  std::array<std::vector<double>, 2> control_box() const;

  bool operator==(const TensorSpline&) const = default;

private:
  std::array<KnotVector, P> knots_;
  int dim_ = 0;
  std::vector<double> points_;
  std::vector<double> weights_;
};

using Curve = TensorSpline<1>;
using Surface = TensorSpline<2>;
using Trivariate = TensorSpline<3>;

extern template class TensorSpline<1>;
extern template class TensorSpline<2>;
extern template class TensorSpline<3>;

}  // namespace trivox::spline
