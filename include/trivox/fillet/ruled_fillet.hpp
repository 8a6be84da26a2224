/// @file trivox/fillet/ruled_fillet.hpp
/// @brief The ruled-volume fillet between two primary surfaces, with its properties blended
/// parametrically.
///
/// Masalha, Cirillo & Elber 2021, Alg. 2: T(u, v, w) = Rld(S^_12, S_b) = (1 - w)
/// S^_12(u, v) + w S_b(u, v), S^_12 = S^_1 joined with S^_2 along C (Eq. 5), after bringing
/// everything into one function space by degree raising and knot refinement. Properties
/// (coordinates 3..k-1) follow Sec. 7.1: S_b carries g_b, whose control points are
/// (1 - a_r) p^(1)_{m,r} + a_r p^(2)_{m,r} with a_r = r / (n_v - 1), and the fillet ruled
/// between g_12 (Eq. 8) and g_b. Eq. 8 lets g_12 jump across C where g_1 and g_2 differ there;
/// a single spline cannot, so the fillet is returned as its two halves, split where S^_12 is
/// joined (v = 1/2): half i is ruled between S^_i and its half of S_b and carries g_i exactly
/// on S^_i. Their geometry is T itself (the split of one trivariate at a knot), glued C0 along
/// the ruling from C to S_b(u, 1/2).
///
/// Orientation: each half has w = 0 on S^_i and w = 1 on S_b; when the Jacobian determinant is
/// negative at the centre, u is reversed in both, so both are right-handed. The faces v = 0
/// (half 1) and v = 1 (half 2) collapse onto the rails, where det J vanishes (Sec. 3.2, 9).
/// Cost: one common-space refinement of three surfaces, then linear in the control points.
#pragma once
#include <array>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::fillet {

/// @param sub1   S^_1(u, v) in R^k: v = 0 on rail 1, v = 1 on C
/// @param sub2   S^_2(u, v) in R^k: v = 0 on C, v = 1 on rail 2; u along C as in sub1
/// @param blend  S_b(u, v): v = 0 on rail 1, v = 1 on rail 2; in R^3 (its properties are then
///               g_b of Sec. 7.1) or in R^k (its properties are used as given)
/// @return the two halves, each in R^k
/// @throws Error (bad_input) for sub-regions of different dimensions or fewer than 3 coordinates,
///         rational inputs, or a blend in neither R^3 nor R^k
std::array<spline::Trivariate, 2> ruled_fillet(const spline::Surface& sub1, const spline::Surface& sub2,
                                               const spline::Surface& blend);

}  // namespace trivox::fillet
