/// @file trivox/fillet/bridge.hpp
/// @brief A flend between disjoint bodies: the trivariate that bridges a face of one cell to a
/// face of another, leaving each cell tangentially.
///
/// Eager & Dannenhoffer 2019 (Flends), Sec. III, made volumetric. Per point (u, v) of the
/// two faces A (of cell 1) and B (of cell 2): the end directions d_A, d_B are the cells' own
/// derivatives across their faces, pointing out of the cells (at the faces' edges these are
/// tangent to the adjacent faces, the directions Sec. III.A asks for); the faux intersection
/// P_I is the average of the closest points C_A, C_B of the lines P_A + t d_A and P_B + s d_B
/// (Sec. III.A's formulas; for parallel lines, the midpoint of P_A and P_B); then the flend
/// section of Sec. II.A with `dip`, with the inner control points on the end lines, P_1 = P_0 +
/// dip |C_A - P_0| d^_A and P_3 = P_4 + dip |C_B - P_4| d^_B, so the bridge is G1 with both
/// cells exactly where the fitted rows are exact and to the angle tolerance in between;
/// P_2 = (P* + P**) / 2, P* = P_1 + dip (P_I - P_1), P** = P_3 + dip (P_I - P_3).
/// T(u, v, w) = sum_r N_r(w) P_r(u, v) with the clamped uniform cubic of five control points in
/// w; P_0 = A and P_4 = B exactly (after bringing B to A's orientation and both into one space),
/// P_1..P_3 interpolated in that space, refined until within tolerance. Properties run linearly
/// in w from A's to B's (Greville rows).
/// Cost: a few evaluations per control point per refinement round.
#pragma once
#include <array>
#include <string>

#include "trivox/spline/extract.hpp"
#include "trivox/spline/tensor_spline.hpp"

namespace trivox::fillet {

struct BridgeOptions {
  double dip = 0.5;  ///< in [0, 1]: 0 gives straight rulings from A to B
  /// Largest angle (radians) between the bridge's w-direction at A or B and the cell's own
  /// direction there, between the samples; > 0.
  double angle_tolerance = 1e-6;
  int max_rounds = 8;  ///< halvings of the rows' knots before giving up (Error failed)
};

struct BridgeQuality {
  std::array<double, 2> g1_angle{0.0, 0.0};  ///< max angle (rad) at A, at B
  double det_min = 0.0, det_max = 0.0;       ///< det J at interior sample points
  std::string orientation;                   ///< how B's (u, v) were matched to A's, e.g. "u reversed"
};

/// The bridge from face fa of cell1 to face fb of cell2 (both in R^k).
/// @throws Error (bad_input) for cells of different dimensions, dip out of range, or faces that
///         meet (a bridge needs disjoint faces: use the fillet); Error (failed) when det J
///         changes sign inside or the rows do not reach the tolerance
spline::Trivariate bridge(const spline::Trivariate& cell1, spline::Face fa, const spline::Trivariate& cell2,
                          spline::Face fb, const BridgeOptions& options = {}, BridgeQuality* quality = nullptr);

}  // namespace trivox::fillet
