/// @file src/spline/tensor_ops.hpp
/// @brief Private helpers of the spline module: one-dimensional linear maps on control polygons,
/// applied to tensor-product control nets one direction at a time (the G+Smo way: write the
/// operation once in 1-D).
#pragma once
#include <Eigen/Dense>
#include <array>
#include <vector>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::spline::detail {

/// Control data as a dense tensor: `extents` entries per direction (first fastest), `H` values
/// per entry.
template <int P>
struct Net {
  std::array<int, P> extents{};
  int H = 0;
  std::vector<double> values;
};

/// The net of `s`: its points, or (w P, w) per point when rational (homogeneous coordinates, in
/// which every linear operation on a rational spline is the polynomial operation).
template <int P>
Net<P> to_net(const TensorSpline<P>& s);

/// The spline with the given knots whose net (homogeneous when `rational`) is `net`.
template <int P>
TensorSpline<P> from_net(std::array<KnotVector, P> knots, int dim, bool rational, Net<P> net);

/// Replaces the extent n of direction d by T.rows(): every line of the net along d, as an n x H
/// matrix L, becomes T * L. T is m x n.
template <int P>
Net<P> apply_along(const Net<P>& net, int d, const Eigen::MatrixXd& T);

/// A banded m x n matrix, the form of refinement, restriction and elevation maps (a few
/// non-zeros per row): row j holds columns first[j] .. first[j] + len - 1, its values
/// vals[start[j] .. start[j + 1]). Memory and work O(non-zeros), where the dense matrix of a
/// thousand-span knot vector's Bezier extraction is m n (hundreds of MB).
struct Banded {
  int cols = 0;
  std::vector<int> first;
  std::vector<std::size_t> start{0};  ///< rows() + 1 offsets into vals
  std::vector<double> vals;

  int rows() const noexcept { return static_cast<int>(first.size()); }
  /// Appends a row whose non-zeros start at column `col`.
  void push_row(int col, const double* v, std::size_t len) {
    first.push_back(col);
    vals.insert(vals.end(), v, v + len);
    start.push_back(vals.size());
  }
  static Banded identity(int n);
  /// Every row's span from its first to its last non-zero entry.
  static Banded from_dense(const Eigen::MatrixXd& T);
  Eigen::MatrixXd dense() const;
  /// Rows first .. first + count - 1.
  Banded middle_rows(int first, int count) const;
};

/// apply_along with a banded T: the same sums in the same order (each row's non-zero entries,
/// by increasing column), so the same floats as with T.dense().
template <int P>
Net<P> apply_along(const Net<P>& net, int d, const Banded& T);

/// The m x n matrix taking the coefficients of a spline in the space of `from` to its coefficients
/// in the space of `to` (which must contain it: `to` is a refinement and/or elevation of `from` on
/// the same domain). Knot insertion uses Boehm's algorithm (exact); other cases use collocation at
/// `to.order()` points per non-empty span, solved by least squares (exact up to rounding, since
/// the system is consistent).
Eigen::MatrixXd transfer_matrix(const KnotVector& from, const KnotVector& to);

/// Row of basis values of `kv` at t: 1 x n (for iso-curves).
Eigen::MatrixXd basis_row(const KnotVector& kv, double t);

/// The knot vector `kv` with the knots `add` inserted (sorted merge).
KnotVector with_knots(const KnotVector& kv, std::vector<double> add);

/// Collocation matrix of `kv` at sample points: samples x n.
Eigen::MatrixXd collocation(const KnotVector& kv, const std::vector<double>& samples);

/// `k` sample points inside every non-empty span of `kv` (Chebyshev nodes of the span, never on a
/// knot, so discontinuities do not matter).
std::vector<double> span_samples(const KnotVector& kv, int k);

/// The clamped knot vector of order `order` on the common domain of the clamped vectors a and b
/// whose breakpoints are theirs, each with the continuity (degree - multiplicity) of the less
/// smooth of the two there: the space of sums (order = max) or of products (order = o_a + o_b - 1).
KnotVector merged_space(const KnotVector& a, const KnotVector& b, int order);

/// The Bezier pieces of a spline in Bezier form along every direction (each interior knot at full
/// multiplicity): piece e (u fastest) spans element el = piece_element(e, spans) of the
/// breakpoint grid, and its local control point r (u fastest) is the net's point
/// piece_point(el, r, orders): disjoint blocks of `order` points per span and direction.
template <int P>
std::array<int, P> piece_element(int e, const std::array<int, P>& spans) {
  std::array<int, P> el{};
  for (std::size_t d = 0; d < P; ++d) {
    el[d] = e % spans[d];
    e /= spans[d];
  }
  return el;
}
template <int P>
std::array<int, P> piece_point(const std::array<int, P>& el, int r, const std::array<int, P>& orders) {
  std::array<int, P> src{};
  for (std::size_t d = 0; d < P; ++d) {
    src[d] = el[d] * orders[d] + r % orders[d];
    r /= orders[d];
  }
  return src;
}

}  // namespace trivox::spline::detail
