/// @file trivox/spline/calculus.hpp
/// @brief Splines built from splines: exact derivatives, products (scalar by scalar, scalar by
/// vector, dot and cross) and sums, so that the Jacobian determinant of a trivariate is itself a
/// spline whose coefficients bound it.
///
/// Derivative: the order drops by one and the coefficients are divided differences (NURBS Book
/// eq. 3.8, per direction). Product: the result lives in the product space (order o_a + o_b - 1,
/// each breakpoint with the continuity of the less smooth factor, Morken 1991); its coefficients
/// are found by collocation at order points per span, which is exact up to rounding because the
/// product lies in that space. Cost of a product: O(prod(samples) * (k_a + k_b)) evaluations plus
/// one small least-squares solve per direction.
/// Polynomial (non-rational) splines only: a derivative or product of rational splines is not a
/// spline of this kind, and these functions throw for them.
#pragma once
#include "trivox/spline/tensor_spline.hpp"

namespace trivox::spline {

/// The partial derivative d/dt_dir as a spline of one lower order in dir.
/// @throws Error for rational splines and for order 1 in dir (piecewise constant)
template <int P>
TensorSpline<P> derivative(const TensorSpline<P>& s, int dir);

/// How the coordinates of two factors combine in `product`.
enum class ProductKind {
  scalar,       ///< a and b scalar (dim 1): a * b
  scalar_vector,///< a scalar, b in R^k: a * b in R^k
  dot,          ///< a and b in R^k: a . b (dim 1)
  cross,        ///< a and b in R^3: a x b
  componentwise,///< a and b in R^k: (a_i * b_i)
};

/// The product spline a (x) b on the common domain.
/// @throws Error on rational inputs, different domains or coordinate counts unfit for `kind`
template <int P>
TensorSpline<P> product(const TensorSpline<P>& a, const TensorSpline<P>& b, ProductKind kind);

/// a + scale * b, both brought into their common space first.
template <int P>
TensorSpline<P> add(const TensorSpline<P>& a, const TensorSpline<P>& b, double scale = 1.0);

/// Coordinates [first, first + count) of s as a spline in R^count (e.g. xyz of a cell with
/// properties).
template <int P>
TensorSpline<P> coordinates(const TensorSpline<P>& s, int first, int count);

/// The Jacobian determinant det[dX/du, dX/dv, dX/dw] of the xyz coordinates of a polynomial
/// trivariate, as a scalar trivariate: du . (dv x dw) (Massarwi & Elber 2016, Sec. 3.3;
/// Fadila, Hong & Elber, Fadila et al. 2023, Sec. 2: validity from the signs of its coefficients).
Trivariate jacobian_determinant(const Trivariate& s);

/// For a planar surface (xy coordinates): det[dX/du, dX/dv] as a scalar surface.
Surface jacobian_determinant(const Surface& s);

}  // namespace trivox::spline
