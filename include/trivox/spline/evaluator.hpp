/// @file trivox/spline/evaluator.hpp
/// @brief Fast evaluation of one spline at many parameters that arrive in coherent order
/// (scanlines: the first parameter varies, the others repeat).
///
/// The evaluator remembers the last knot spans (so span search is O(1) for nearby parameters)
/// and, when the slower parameters repeat, contracts the control net over them once: for fixed
/// (v, w) a trivariate becomes a curve in u, and each further point on that line costs one curve
/// evaluation, O(order_u * k) instead of O(order_u * order_v * order_w * k). For fixed w it also
/// keeps the iso-surface, so the next lines of a layer are cheap too. Caches are built on the
/// second request with the same slower parameters, so random parameters cost one plain
/// evaluation each. Results equal TensorSpline::eval up to rounding (the sums are reordered).
/// Rational splines are evaluated directly (no caching). Not thread-safe: one per thread.
#pragma once
#include <array>
#include <vector>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::spline {

template <int P>
class Evaluator {
public:
  using Params = std::array<double, P>;

  /// @param s  the spline; must outlive the evaluator and stay unchanged
  explicit Evaluator(const TensorSpline<P>& s);

  /// The point at t (dim() values), as TensorSpline::eval.
  void eval(const Params& t, double* out);
  /// The point and its first partials at t: (1 + P) x dim() values (value, d/dt_0, ..).
  void eval_first(const Params& t, double* out);

private:
  struct Basis1 {
    int first = 0;
    double N[2][16];  // values, first derivatives (order <= 16 on the cached path); filled by basis_at
  };
  void basis_at(int d, double t, bool derivs, Basis1& b);
  void build_line(const Params& t, bool derivs);
  void build_slab(double w, bool derivs);
  void eval_on_line(double u, bool derivs, double* out);
  bool cacheable() const noexcept;

  const TensorSpline<P>* s_;
  int dim_;
  /// The curve evaluation on a cached line, specialised for the order along it and dim().
  void (*line_kernel_)(int order, int dim, int lines, const double* N, const double* dN, const double* const* lines_at,
                       double* out);
  int hint_[3] = {0, 0, 0};
  // Line cache: the net contracted over directions 1..P-1 at fixed parameters (n_0 x dim each:
  // value, then d/dt_1 and d/dt_2 when built with derivatives).
  bool line_valid_ = false, line_derivs_ = false;
  std::array<double, 2> line_key_{}, prev_line_key_{};
  bool have_prev_line_key_ = false;
  std::vector<double> line_[3];
  // Slab cache (P = 3): the net contracted over w at fixed w (n_0 x n_1 x dim: value, d/dw).
  bool slab_valid_ = false, slab_derivs_ = false;
  double slab_key_ = 0.0, prev_line_w_ = 0.0;
  bool have_prev_line_w_ = false;
  std::vector<double> slab_[2];
};

extern template class Evaluator<1>;
extern template class Evaluator<2>;
extern template class Evaluator<3>;

}  // namespace trivox::spline
