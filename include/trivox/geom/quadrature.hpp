/// @file trivox/geom/quadrature.hpp
/// @brief Gauss-Legendre quadrature and the integrals of a trivariate's Jacobian determinant:
/// the volume of a cell and the integral of a property over it.
///
/// Integrals run over the Bezier elements (non-empty knot spans) with a tensor Gauss rule per
/// element. For a polynomial cell of degrees (p_u, p_v, p_w) the Jacobian determinant has degree
/// 3 p_d - 1 in direction d, so ceil(3 p_d / 2) points per direction integrate it exactly (the
/// volume is exact up to rounding); rational cells use 3 p_d + 2 points (not exact: the
/// determinant is rational). Cost: O(elements * prod(points) * evaluation). The integrals first
/// check every order against the process's default limits (trivox/limits.hpp, max_order) and
/// throw trivox::Error (bad_input) for a cell above it, before building a rule.
#pragma once
#include <vector>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::geom {

/// Gauss-Legendre nodes and weights on [-1, 1], exact for polynomials of degree 2n - 1.
struct GaussRule {
  std::vector<double> nodes, weights;
};
/// @param n  number of points, 1..4096 (time O(n^2), memory O(n))
/// @throws trivox::Error (bad_input) for n outside 1..4096
GaussRule gauss_legendre(int n);

/// The signed volume: the integral of det[dX/du, dX/dv, dX/dw] over the parametric domain
/// (positive for a right-handed parametrisation, negative for a left-handed one).
double signed_volume(const spline::Trivariate& cell);

/// |signed_volume|: the volume of a valid cell (whose determinant keeps one sign).
double volume(const spline::Trivariate& cell);

/// The integral of coordinate `coord` (3.. for properties) over the cell's volume:
/// int f |det J| du dv dw, with one more Gauss point per direction for the property's degree.
double integrate_coordinate(const spline::Trivariate& cell, int coord);

}  // namespace trivox::geom
