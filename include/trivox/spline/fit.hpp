/// @file trivox/spline/fit.hpp
/// @brief Least-squares fitting and interpolation of B-spline curves and surfaces to data in R^k,
/// with optional pinned control points (pinned boundary rows, so that a fitted surface
/// interpolates given boundary curves).
///
/// Piegl & Tiller, The NURBS Book, 2nd ed., Ch. 9:
///  - 9.2.1 global curve interpolation: parameters by chord length (eq. 9.4-9.5) or centripetal
///    (eq. 9.6), knots by averaging (eq. 9.8), one collocation system;
///  - 9.2.5 global surface interpolation: the tensor system solved one direction at a time;
///  - 9.4.1 least-squares curve approximation: knots by eq. 9.68-9.69, end control points fixed
///    by eliminating their columns (here any set of control points may be fixed);
///  - 9.4.3 least-squares surface approximation (gridded data: one direction at a time, exact
///    because the pseudo-inverse of a Kronecker product is the Kronecker product of the
///    pseudo-inverses).
///
/// Every problem is min ||A x - b|| over the free control points, A the collocation matrix
/// (A_jl = N_l(t_j), `order` non-zeros per row and direction), solved by a banded QR
/// factorisation built from Givens rotations, one data row at a time (as FITPACK does: Dierckx,
/// Curve and Surface Fitting with Splines, 1993; Lawson & Hanson, Solving Least Squares
/// Problems, Ch. 27), then Eigen's triangular solve: no normal equations, so the condition
/// number is not squared. Data need not be ordered. Before solving, the Schoenberg-Whitney
/// condition (the system has full column rank iff the sorted parameters hold a strictly
/// increasing subsequence t_(j_0) < t_(j_1) < ... with N_l(t_(j_l)) != 0 for every free l) is
/// checked per direction, so an under-determined system is reported by naming the control point
/// that no data determines.
///
/// Errors: trivox::Error, `bad_input` for inconsistent sizes, parameters outside the domain,
/// under-determined systems and boundary curves outside the surface's space; `failed` when a
/// system that satisfies Schoenberg-Whitney is still numerically rank deficient.
///
/// Cost, for m data, n control points of order k per direction and dim coordinates: curves
/// O(m k (k + dim)); gridded surfaces O(m_u m_v (k_u + k_v) dim), one 1-D solve per direction
/// with all grid lines as right-hand sides; scattered surfaces O(m w (w + dim)) with bandwidth
/// w = k_u + n_u (k_v - 1) (or the same with u and v exchanged, whichever is smaller).
#pragma once
#include <array>
#include <optional>
#include <span>
#include <vector>

#include "trivox/spline/knot_vector.hpp"
#include "trivox/spline/tensor_spline.hpp"

namespace trivox::spline {

// ---------------------------------------------------------------------------------------------
// Parameters and knots

/// Parameters for points Q_0..Q_{m-1} in R^dim from their accumulated distances:
/// t_0 = 0, t_j = t_{j-1} + |Q_j - Q_{j-1}|^exponent, then divided by t_{m-1} (so t in [0, 1]).
/// @param points    m x dim values, point after point, in curve order (m >= 2)
/// @param dim       coordinates per point (>= 1)
/// @param exponent  1: chord length (NURBS Book eq. 9.5); 0.5: centripetal (eq. 9.6); 0: uniform
/// @throws Error (bad_input) when all points coincide (zero total length) or sizes mismatch
std::vector<double> chord_length_params(std::span<const double> points, int dim,
                                        double exponent = 1.0);

/// Knots for interpolating at `params` with the given order: clamped at min(params) and
/// max(params), interior knots the averages of `order - 1` consecutive sorted parameters
/// (NURBS Book eq. 9.8), so every basis function gets a parameter inside its support.
/// Order 1 puts the interior knots midway between neighbouring parameters.
/// @param params  m values, any order, m >= order, not all equal
/// @return a knot vector of m + order knots (m basis functions)
KnotVector interpolation_knots(std::span<const double> params, int order);

/// Knots for a least-squares fit with `count` control points at `params` (NURBS Book eq.
/// 9.68-9.69): clamped at min and max of params, interior knots placed so that every knot span
/// holds at least one parameter (the Schoenberg-Whitney condition holds for distinct params).
/// Order 1 shifts the knots by half a parameter so that they fall between parameters.
/// @param params  m values, any order, m >= count
/// @param order   degree + 1 (>= 1)
/// @param count   number of control points, order <= count <= m
KnotVector fitting_knots(std::span<const double> params, int order, int count);

// ---------------------------------------------------------------------------------------------
// Curves

/// Control points a fit must keep as given (the other control points are fitted).
struct CurvePins {
  std::vector<int> rows;       ///< control point indices, distinct, each in [0, n)
  std::vector<double> points;  ///< rows.size() x dim values: the pinned control points, in `rows` order

  /// Pins control points 0 and count-1 to `first` and `last` (dim values each). With clamped
  /// knots the curve then starts at `first` and ends at `last` (NURBS Book 9.4.1).
  static CurvePins ends(int count, std::span<const double> first, std::span<const double> last);
  bool empty() const noexcept { return rows.empty(); }
};

/// The curve of the given knots through the data: C(params[j]) = values[j], a square collocation
/// system (NURBS Book 9.2.1).
/// @param params  m parameters in the knots' domain, any order; m must equal knots.size()
/// @param dim     coordinates per data point (>= 1)
/// @param values  m x dim values, values[j*dim + c] = coordinate c of the point at params[j]
/// @param knots   the curve's knot vector (e.g. interpolation_knots(params, order))
/// @throws Error (bad_input) on size mismatches or when the Schoenberg-Whitney condition fails
///         (sorted params t_(l) must satisfy N_l(t_(l)) != 0, l = 0..m-1)
Curve interpolate_curve(std::span<const double> params, int dim, std::span<const double> values,
                        const KnotVector& knots);

/// interpolate_curve with interpolation_knots(params, order).
Curve interpolate_curve(std::span<const double> params, int dim, std::span<const double> values,
                        int order);

/// The least-squares curve: control points minimising sum_j |C(params[j]) - values[j]|^2 over
/// the curve's free control points, the pinned ones held at their given values (NURBS Book
/// 9.4.1). With as many data as free control points this interpolates.
/// @param params  m parameters in the knots' domain, any order (repeats allowed)
/// @param dim     coordinates per data point (>= 1)
/// @param values  m x dim values, values[j*dim + c] = coordinate c of the point at params[j]
/// @param knots   the curve's knot vector, n = knots.size() control points
/// @param pins    control points kept as given (dim coordinates each)
/// @throws Error (bad_input) on size mismatches, bad pins, fewer data than free control points or
///         a Schoenberg-Whitney violation (names the first control point no parameter determines)
Curve fit_curve(std::span<const double> params, int dim, std::span<const double> values,
                const KnotVector& knots, const CurvePins& pins = {});

// ---------------------------------------------------------------------------------------------
// Surfaces

/// Boundary rows of a surface's control net that a fit keeps as given. Side s names where one
/// parameter is at an end of its domain, as for cell faces: u0 (u = u_min), u1 (u = u_max),
/// v0 (v = v_min), v1 (v = v_max). The u0/u1 rows are the n_v control points (0 or n_u-1, j);
/// the v0/v1 rows are the n_u control points (i, 0 or n_v-1).
/// A side is pinned either by a boundary curve or by explicit control rows, not both. Where two
/// pinned sides meet, their corner control points must agree (up to 1e-10 relative).
struct SurfacePins {
  enum Side : int { u0 = 0, u1 = 1, v0 = 2, v1 = 3 };

  /// curves[s]: the curve the fitted surface must equal on side s. u0/u1 take a curve in v,
  /// S(u_min, v) = C(v); v0/v1 a curve in u, S(u, v_min) = C(u). The curve must have `dim`
  /// coordinates, be polynomial (or all weights equal), have the surface's domain in its
  /// parameter, and lie in the surface's spline space of that parameter (e.g. a lower order or
  /// a subset of the knots); it is re-expressed there exactly (refine.hpp, to_space). The
  /// surface's knots across the side must interpolate that end (clamped there).
  std::array<std::optional<Curve>, 4> curves;
  /// rows[s], when non-empty: the control points of side s, count x dim values (count = n_v for
  /// u0/u1, n_u for v0/v1), in increasing index order.
  std::array<std::vector<double>, 4> rows;

  bool pinned(Side s) const noexcept { return curves[s].has_value() || !rows[s].empty(); }
  bool empty() const noexcept {
    return !pinned(u0) && !pinned(u1) && !pinned(v0) && !pinned(v1);
  }
};

/// The least-squares surface to scattered data: control points minimising
/// sum_j |S(u_j, v_j) - values[j]|^2 over the control points not pinned by `pins`.
/// @param uv      m x 2 parameters (u_j, v_j), each in the knots' domains, any order
/// @param dim     coordinates per data point (>= 1)
/// @param values  m x dim values, values[j*dim + c] = coordinate c of the point at (u_j, v_j)
/// @param knots   knot vectors in u and v; n_u x n_v control points
/// @param pins    boundary rows kept as given
/// @throws Error (bad_input) on size mismatches, bad pins, a control point whose support holds
///         no data, or data that do not determine the free control points (rank deficiency)
Surface fit_surface(std::span<const double> uv, int dim, std::span<const double> values,
                    const std::array<KnotVector, 2>& knots, const SurfacePins& pins = {});

/// The least-squares surface to gridded data: the point at (u[a], v[b]) is given for every a, b.
/// Solved one direction at a time (NURBS Book 9.2.5, 9.4.3); exactly the least-squares solution
/// of the full tensor system, also with pins (pinned rows are whole rows, so the free control
/// points remain a tensor grid). With m_u = n_u and m_v = n_v this interpolates the grid.
/// @param u       m_u parameters in knots[0]'s domain, any order
/// @param v       m_v parameters in knots[1]'s domain, any order
/// @param dim     coordinates per data point (>= 1)
/// @param values  m_u x m_v x dim values, u fastest: values[(a + m_u*b)*dim + c] is coordinate c
///                of the point at (u[a], v[b])
/// @param knots   knot vectors in u and v; n_u x n_v control points
/// @param pins    boundary rows kept as given
/// @throws Error (bad_input) on size mismatches, bad pins or a Schoenberg-Whitney violation in
///         either direction
Surface fit_surface_grid(std::span<const double> u, std::span<const double> v, int dim,
                         std::span<const double> values, const std::array<KnotVector, 2>& knots,
                         const SurfacePins& pins = {});

/// fit_surface_grid with knots interpolation_knots(u, orders[0]), interpolation_knots(v, orders[1]):
/// the surface through every grid point.
Surface interpolate_surface_grid(std::span<const double> u, std::span<const double> v, int dim,
                                 std::span<const double> values, std::array<int, 2> orders);

}  // namespace trivox::spline
