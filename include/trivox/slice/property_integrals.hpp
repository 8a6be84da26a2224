/// @file trivox/slice/property_integrals.hpp
/// @brief The integral of every property over a cell or a Boolean's piece, int_P rho_k dV (the
/// mass of a material whose fraction or density the property is), where it can be computed
/// exactly, and why not elsewhere.
///
/// Plain cells: Gauss quadrature of rho_k |det J| over the trivariate's Bezier elements
/// (geom::integrate_coordinate), exact up to rounding for polynomial cells with a Jacobian of one
/// sign; rational cells converge but are not exact (the determinant is rational).
///
/// Trimmed pieces (Booleans). A property is a polynomial of the trivariate's parameters, not of
/// x, so the divergence theorem on the piece's boundary faces (slice::piece_measures) needs the
/// faces in the parameter space of the trivariate: U = X^{-1}(S). That is a polynomial patch, and
/// the integral exact, when X is affine, X(u) = X_0 + A (u - u_lo), as the box primitives and
/// their Booleans are. Then, with Omega = X^{-1}(P) and R(u, v, w) = int_{u_lo}^{u} rho(u', v, w) du'
/// (dR/du = rho),
///   int_P rho dV = |det A| int_Omega rho du = det A sum_faces orientation int R(U) (U_s x U_t)_u ds dt,
/// U_s x U_t = det(A^-1) A^T (S_s x S_t) carrying the sign of det A (the faces are oriented
/// outward in xyz). R is the Gauss rule of ceil((p_u + 1) / 2) points on [u_lo, u], exact for a
/// trivariate of one knot span (one polynomial); R(U) (U_s x U_t)_u has degree
/// (p_u + 1 + p_v + p_w + 2) q - 1 in a patch direction of degree q, which a Gauss rule of
/// ceil((p_u + p_v + p_w + 3) q / 2) points integrates exactly. The result is then exact up to
/// rounding and to how closely the boundary faces meet (as piece_measures' volume); `volume`,
/// the same sum with rho = 1, checks it against piece_measures.
///
/// Not computed (`values` empty, `note` says why): a trimmed piece whose trivariate is not affine
/// (X^{-1}(S) is not polynomial: the untrimming of trimmed V-cells into trivariates, Massarwi &
/// Elber 2016, Sec. 7, would be needed, and trivox does not build it), of several knot spans
/// (R is piecewise across the knots and the faces are not split there), rational, or whose
/// properties blend its inputs' (an intersection's cells: the value is not the trivariate's own
/// polynomial).
///
/// Cost: plain cells, one Gauss rule per Bezier element; trimmed pieces, slice::boundary_faces
/// (the surface intersections, trimming and untrimming) and per Bezier piece of every patch
/// n_s n_t (1 + ceil((p_u + 1) / 2)) evaluations.
#pragma once
#include <string>
#include <vector>

#include "trivox/slice/boundary_faces.hpp"
#include "trivox/vmodel/vmodel.hpp"

namespace trivox::slice {

struct PropertyIntegrals {
  /// int_P rho_k dV per property of the model (its order); empty when not computed.
  std::vector<double> values;
  /// The same integral of rho = 1 (the volume), as a check; 0 when not computed.
  double volume = 0.0;
  /// Exact up to rounding (polynomial integrands, Gauss rules of enough points); false for
  /// rational plain cells (converged quadrature).
  bool exact = false;
  /// "quadrature" (plain cells), "boundary" (trimmed pieces), "" when not computed.
  std::string method;
  /// Why the integrals were not computed ("" when they were).
  std::string note;
};

/// The property integrals of `model.cells[cell]` (see the file comment).
/// @throws trivox::Error (bad_input) for a cell out of range; and as geom::integrate_coordinate
///         and boundary_faces (whose errors piece_measures reports first)
PropertyIntegrals property_integrals(const vmodel::VModel& model, int cell, const BoundaryFaceOptions& options = {});

}  // namespace trivox::slice
