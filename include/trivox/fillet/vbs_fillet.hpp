/// @file trivox/fillet/vbs_fillet.hpp
/// @brief The volumetric-Boolean-sum fillet: the fillet space between S^_1, S^_2 and S_b divided
/// into three cube-like cells, each the volumetric Boolean sum of its four sleeve surfaces and
/// two Coons caps. No face collapses to a curve.
///
/// Masalha, Cirillo & Elber 2021, Sec. 3.2 and Alg. 3, with the division of
/// Appendix A / Alg. 7. The cross-section of the fillet space is a curvilinear triangle with
/// corners C (where S^_1 meets S^_2) and the rails R_1, R_2 (where S_b meets S^_i):
///
/// - C_b(u) = S_b(u, v_b), v_b from the orthogonal projection of C(1/2) on S_b(1/2, v) (Eq. A.1);
/// - C_c = C + rho (C_b - C), rho = sqrt 2 / (1 + sqrt 2) (Eq. A.2: in a right-angled corner with
///   a 45-degree chamfer C_c(1/2) is then the incentre, equidistant from the three surfaces);
/// - C_i(u) = S^_i(u, v_i), v_i from the projection of C_c(1/2) on S^_i(1/2, v).
///
/// The ruled surfaces D_1 = Rld(C_1, C_c), D_2 = Rld(C_c, C_2), D_b = Rld(C_b, C_c) split the
/// space into T_1 (at C: S^_1[v_1, 1], D_1, D_2, S^_2[0, v_2]), T_2 (at rail 1: S^_1[0, v_1],
/// S_b[0, v_b], D_b, D_1) and T_3 (at rail 2: S_b[v_b, 1], S^_2[v_2, 1], D_2, D_b), Alg. 3's
/// cross-section curves 1-4, 5-7 and 2, 8-9 and 3, 7. Each cell is the volumetric Boolean sum
/// of six faces: its four sleeve surfaces and, at u = 0 and u = 1, the Coons patches (Boolean
/// sums, Cohen et al. 2001) of the sleeve's end curves. With Coons caps the six-face sum loses
/// its u terms and is, at every u, the Coons patch of the cross-section's four curves
/// (T = Pv + Pw - Pvw); it is built so, directly in the sleeve's spaces (the same cell as
/// construct::boolean_sum of the six faces, to rounding, without converting order-2 blends into
/// the thousand-knot space along C).
///
/// Parametrisation (after normalising every input to [0, 1]^2): u along C in all three cells;
/// (v, w) span the cross-section, T(u, v, w) with corners (v, w) = (0, 0), (1, 0), (0, 1), (1, 1)
///   T_1: C_1, C_c, C, C_2   faces v0 = S^_1[v_1, 1], v1 = D_2, w0 = D_1, w1 = S^_2[0, v_2]
///   T_2: R_1, C_b, C_1, C_c faces v0 = S^_1[0, v_1], v1 = D_b, w0 = S_b[0, v_b], w1 = D_1
///   T_3: C_b, R_2, C_c, C_2 faces v0 = D_b, v1 = S^_2[v_2, 1] reversed, w0 = S_b[v_b, 1], w1 = D_2
/// so the three cross-sections have the same orientation; when det J is negative at the centre,
/// u is reversed in all three. Every sleeve surface is brought into one function space (u: the
/// inputs' common space; across: the union of all pieces' spaces), each shared edge is one set of
/// control points, and each cell's boundary layers are set to its faces' control points: the
/// shared faces D_1 (T_1 w0 = T_2 w1), D_2 (T_1 v1 = T_3 w1), D_b (T_2 v1 = T_3 v0) are
/// bit-identical in both cells, the outer faces are the input pieces' control nets.
///
/// Properties (R^k, k > 3): the sleeve surfaces carry them, so the Boolean sums continue g_1 on
/// S^_1, g_2 on S^_2 and g_b on S_b (Sec. 7.1, computed as the ruled fillet does when S_b is in
/// R^3); D_1, D_2, D_b are ruled in the properties too, C_c's being C's (the mean of g_1 and g_2
/// there) moved rho towards g_b(u, v_b). Where g_1 and g_2 differ on C (Eq. 8's jump), the one
/// cell T_1 at C cannot carry both: its edge C gets the mean, and its faces on S^_i deviate from
/// g_i by up to half the jump, fading within the first span from C (VbsReport::property_jump).
/// T_2 and T_3 carry g_i exactly on their S^_i faces.
///
/// Jacobians: T_1 has no degenerate edge (the angle at C is the faces' dihedral angle). T_2 and
/// T_3 each have one zero-angle edge, the rail, where S_b is tangent to S^_i (G1): det J vanishes
/// along it (Masalha et al. 2021, Sec. 9, "at the rail curves, the Jacobian of all presented
/// approaches vanish"), positive elsewhere when the division does not fold.
///
/// Knots across that come from different pieces (restrictions, normalisations, reversal) and
/// agree to 1e-11 are merged, and a projection parameter within 1e-11 of a knot is moved onto it,
/// so no sliver spans arise (they made det J noise of either sign).
///
/// Cost: one common-space refinement of three surfaces and one of nine sleeve surfaces across
/// (the direction along C is never converted), then linear in the control points of the result:
/// 1207 x 5 x 5 per cell for a cylinder on a floor in 0.06 s (the ruled fillet: 0.06 s).
#pragma once
#include <array>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::fillet {

struct VbsOptions {
  /// rho of Eq. A.2: C_c = C + rho (C_b - C), in (0, 1). sqrt 2 / (1 + sqrt 2) = 2 - sqrt 2.
  double ratio = 0.58578643762690485;
  /// Largest gap allowed between boundaries that must coincide (S^_1(u, 1) and S^_2(u, 0); S_b's
  /// rows on the rails and S^_i's), relative to the diagonal of S_b's control box. They are
  /// joined exactly (C to the mean, S_b's rails to S^_i's) before the construction.
  double tolerance = 1e-6;
};

/// What the division (Appendix A) chose and what the construction found.
struct VbsReport {
  double v_b = 0.0;   ///< C_b = S_b(u, v_b)
  double v_1 = 0.0;   ///< C_1 = S^_1(u, v_1)
  double v_2 = 0.0;   ///< C_2 = S^_2(u, v_2)
  spline::Curve centre;  ///< C_c(u) in R^k
  double c_gap = 0.0;    ///< largest distance between S^_1(u, 1) and S^_2(u, 0) (control points) before the join
  std::array<double, 2> rail_gap{0.0, 0.0};  ///< the same between S_b's rails and S^_i's
  /// Largest |g_1 - g_2| over C's control points: T_1's faces on S^_i deviate from g_i by up to
  /// half of it (0 when the properties agree on C, or without properties).
  double property_jump = 0.0;
  bool reversed = false;  ///< u was reversed to make det J positive
};

/// @param sub1   S^_1(u, v) in R^k: v = 0 on rail 1, v = 1 on C
/// @param sub2   S^_2(u, v) in R^k: v = 0 on C, v = 1 on rail 2; u along C as in sub1
/// @param blend  S_b(u, v): v = 0 on rail 1, v = 1 on rail 2; in R^3 (its properties are then
///               g_b of Sec. 7.1) or in R^k (its properties are used as given, except on the
///               rails, where they become g_i)
/// @return {T_1 at C, T_2 at rail 1, T_3 at rail 2}, each in R^k on [0, 1]^3 (see the file
///         comment for their faces)
/// @throws Error (bad_input) for the inputs ruled_fillet refuses, a ratio outside (0, 1), or
///         boundaries apart by more than the tolerance; Error (failed) for a division that leaves
///         the fillet (a projection parameter v_b, v_i at the end of its range: a folded section)
///         or when the three cells' det J at their centres disagree in sign (the division folds)
std::array<spline::Trivariate, 3> vbs_fillet(const spline::Surface& sub1, const spline::Surface& sub2,
                                             const spline::Surface& blend, const VbsOptions& options = {},
                                             VbsReport* report = nullptr);

}  // namespace trivox::fillet
