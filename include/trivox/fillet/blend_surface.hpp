/// @file trivox/fillet/blend_surface.hpp
/// @brief The blending surface S_b between two rails: the cubic Hermite surface of Masalha,
/// Cirillo & Elber 2021 (Masalha et al. 2021, Sec. 1.1-1.4, Eq. 1, Alg. 1), or the flend
/// cross-section of Eager & Dannenhoffer (Sec. II.A) with its `dip`.
///
/// Both interpolate the rail curves C_1^r(t), C_2^r(t) exactly (they are taken as given, in the
/// caller's function space) and leave them in the primary surfaces' tangent planes (G1), which
/// holds exactly at the sample parameters and to `angle_tolerance` in between:
/// - Hermite: S_b(u, v) = C_1 h00(v) + C_2 h01(v) + tau T_1 h10(v) + tau T_2 h11(v). The tangent
///   fields T_i(t) = C_i^r'(t) x N_i(c_i^r(t)) (Sec. 1.3) are normalised and scaled by
///   tau |C_1(t) - C_2(t)| (so tau is relative to the width of the fillet; about 1.17 follows a
///   circular arc across a right-angled corner with equal distances), oriented so T_1 points from
///   rail 1 towards C and T_2 from C towards rail 2. Normalisation is not polynomial: the field
///   is interpolated in the rails' function space (the approximation Sec. 1.3 calls for, after
///   Kim & Elber 1997; at least cubic), its knots halved until the field leaves the tangent
///   plane by at most the angle tolerance between the samples.
/// - Flend: per t, P_I is the intersection of the tangent plane of S_1 at C_1(t), that of S_2 at
///   C_2(t) and C's normal plane at C(t); the section is the clamped uniform cubic B-spline with
///   control points P_0 = C_1, P_1 = P_0 + dip (P_I - P_0), P_2 = (P* + P**) / 2 with P* = P_1 +
///   dip (P_I - P_1), P** = P_3 + dip (P_I - P_3), P_3 = P_4 + dip (P_I - P_4), P_4 = C_2. All are
///   affine in C_1, C_2 and P_I, so only P_I(t) is interpolated (as above). dip = 0 gives the
///   chamfer: the straight segment between the rails. Flends ask for degree 1 along the edge;
///   here the section's control points follow the rails' spline space instead, so S_b is as
///   smooth along C as the rails are.
/// Cost: a few evaluations per sample and one curve interpolation per halving round.
#pragma once
#include <array>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::fillet {

enum class Section { hermite, flend };
/// "hermite", "flend".
const char* section_name(Section s) noexcept;
bool section_from_name(const char* name, Section& out) noexcept;

struct BlendOptions {
  Section section = Section::hermite;
  double tau = 1.0;   ///< Hermite: tangent magnitude relative to |C_1 - C_2|, in (0, 10]
  double dip = 0.5;   ///< flend: in [0, 1]
  /// Largest angle (radians) between S_b and a primary surface's tangent plane along a rail,
  /// from the approximation of the tangent field (or of P_I), > 0.
  double angle_tolerance = 1e-7;
  int max_rounds = 12;  ///< halvings of the field's knots before giving up (Error failed)
};

/// What S_b is built from. All curves share the parameter t and its domain [0, 1].
struct BlendInput {
  std::array<const spline::Surface*, 2> faces{};  ///< the primary surfaces S_1, S_2 (xyz used)
  std::array<spline::Curve, 2> rail_uv;           ///< c_i^r(t), in face i's parameters
  std::array<spline::Curve, 2> rail;              ///< C_i^r(t) = S_i(c_i^r(t)) in R^3: S_b(u, 0), S_b(u, 1)
  spline::Curve center;                           ///< C(t), the intersection curve, in R^3
};

struct BlendReport {
  /// Largest angle (radians) found between the field (T_i, or P_I - C_i) and face i's tangent
  /// plane at check points between the samples.
  std::array<double, 2> angle{0.0, 0.0};
  int rounds = 0;  ///< halvings needed
};

/// S_b(u, v): u = t along the rails, v from rail 1 (v = 0) to rail 2 (v = 1), in R^3.
/// @throws Error (bad_input) for tau or dip out of range or curves of the wrong dimension;
///         Error (failed) where the construction degenerates (rails meeting, tangent planes
///         parallel to C's normal plane) or the field cannot reach the angle tolerance
spline::Surface blending_surface(const BlendInput& input, const BlendOptions& options = {},
                                 BlendReport* report = nullptr);

}  // namespace trivox::fillet
