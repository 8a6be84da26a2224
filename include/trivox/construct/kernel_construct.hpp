/// @file trivox/construct/kernel_construct.hpp
/// @brief Kernel-based Boolean sum, half Boolean sum and ruling: constructions that keep the
/// regular constructor's boundary but move every interior control point to a kernel point of
/// that boundary, adding degrees of freedom until the Jacobian is valid.
///
/// Fadila, Hong & Elber, Sec. 4, Alg. 1 (planar surfaces from curves; trivariates from
/// surfaces likewise, Sec. 5 end): S_0 = the regular construction; if S_0 is valid, return it;
/// else K = the centroid of the (conservative, Hong & Elber 2022) kernel of S_0's boundary
/// (geom/kernel.hpp); no kernel: fail; else for i = 0..max_dof, S_i = S_0 refined with i uniform
/// knots per span (or degree-raised i times) in every direction, its interior control points
/// (neither first nor last along any direction, so the boundary is untouched: Lemmas 1-3 still
/// hold) moved to K; the first valid S_i is the result. Theorem 4: for a kernel point K, the
/// Jacobian is non-negative in the limit, but may vanish where adjacent control points coincide
/// at K. So, as in the paper, acceptance by default is det J >= 0 (Acceptance::nonnegative); the
/// Sec. 6 variant (`spread` > 0) puts the interior points on a small uniform grid centred at K
/// instead, so no two coincide and a strictly positive Jacobian (Acceptance::positive, the
/// verdict of geom::check_validity) becomes reachable.
///
/// Only the geometric coordinates move (x, y for surfaces; x, y, z for trivariates); properties
/// (further coordinates) keep the values of the regular construction.
///
/// Cost: one kernel (see geom/kernel.hpp) and up to max_dof + 1 validity checks of growing
/// splines (degree raising to degree p + i, or (i + 1) times as many spans per direction).
#pragma once
#include <array>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "trivox/construct/constructors.hpp"
#include "trivox/geom/kernel.hpp"
#include "trivox/geom/validity.hpp"

namespace trivox::construct {

/// The regular constructor the kernel-based one starts from.
enum class KernelOp { boolean_sum, half_boolean_sum, ruled };
/// "boolean_sum", "half_boolean_sum", "ruled" (the names of the construct input format).
const char* kernel_op_name(KernelOp op) noexcept;
/// @throws trivox::Error (bad_input) for any other name
KernelOp kernel_op_from_name(std::string_view name);

/// How degrees of freedom are added per iteration (Fadila et al. 2023, Alg. 1, AddDOF).
enum class AddDof {
  refine,   ///< i uniform knots inserted in every span of every direction
  elevate,  ///< every direction's degree raised i times
};

/// What counts as a valid result.
enum class Acceptance {
  /// det J >= 0 with the boundary's orientation (zero allowed where interior points coincide at
  /// K: Fadila et al. 2023, Theorem 4 and Sec. 5, the criterion of the paper's success rates).
  /// Checked like geom::check_validity (Bezier coefficients of det J, subdivision), with
  /// coefficients within 1e-9 of the largest |coefficient| counted as zero.
  nonnegative,
  /// det J > 0 everywhere: geom::check_validity's verdict `valid`.
  positive,
};

/// Where the interior control points go (Fadila et al. 2023, Alg. 1 line 9; Sec. 7).
enum class KernelPoint {
  /// The centroid of the conservative kernel, at every iteration (the paper's Alg. 1).
  centroid,
  /// The centroid first; when S_i is not accepted there, the centroid of the part of the kernel
  /// where det J's Bezier coefficients (pieces subdivided up to `fit_subdivisions` times where
  /// needed) all have the boundary's sign, if that part has positive area (volume). Fadila et al.
  /// 2023 Sec. 7 names "a more careful selection of the interior kernel location" as the degree of
  /// freedom the paper did not exercise. With every interior point at K (or at K plus the fixed
  /// Sec. 6 offsets), det J is affine in K: the cross (triple) products of the derivatives lose
  /// every term with K twice, since K x K = 0. So each coefficient is a half-plane (half-space)
  /// in K, and any K in their intersection gives det J >= 0 by the convex hull property. The
  /// acceptance check is still the exact one; the point stays inside the boundary's kernel, so
  /// Theorem 4 still applies as more freedom is added.
  fitted,
};

struct KernelConstructOptions {
  AddDof add_dof = AddDof::refine;
  /// Largest number of knots per span (refine) or degree raisings (elevate) tried: iterations
  /// i = 0..max_dof. The paper: 20 knots per span; degree up to 17 (40 for quadratic ruling).
  int max_dof = 20;
  /// Fadila et al. 2023, Sec. 6: 0 moves every interior point to K; s > 0 spreads them on a uniform
  /// grid centred at K, s times the kernel's size wide (sqrt(area), cbrt(volume)) along axes taken
  /// from the control net (first to last layer per direction).
  double spread = 0.0;
  Acceptance acceptance = Acceptance::nonnegative;
  KernelPoint kernel_point = KernelPoint::centroid;
  /// KernelPoint::fitted: how many times a Bezier piece of det J whose coefficients can have the
  /// wrong sign inside the kernel is halved in every direction before its coefficients become
  /// constraints (each halving tightens them: the region only grows).
  int fit_subdivisions = 3;
  /// KernelPoint::fitted, planar surfaces: the kernel the fitted point is taken from, tighter
  /// than `kernel` (still inside the true kernel: refinement only grows the conservative kernel
  /// towards it). Trivariates use `kernel` (each 3-D refinement quadruples a face's constraints).
  geom::KernelOptions fit_kernel{6};
  /// KernelPoint::fitted: when neither the centroid nor the fitted point is accepted at an
  /// iteration, one more try before adding freedom: the interior points on the Sec. 6 grid,
  /// `retry_spread` x kernel size wide, centred at the point fitted for that grid (det J stays
  /// affine in the centre). 0: no retry.
  double retry_spread = 0.0;
  int ruling_order = 3;             ///< order of the ruling direction (Fadila et al. 2023, Sec. 5.1: 3)
  geom::KernelOptions kernel{};     ///< refinement of the kernel computation
  geom::ValidityOptions validity{}; ///< subdivision limits of the validity checks
  /// Boundary matching of the regular constructors; geometry_coords -1 means 2 for surfaces
  /// from planar curves, 3 for trivariates.
  MatchOptions match{};
};

template <int P>
struct KernelResult {
  /// geom::check_validity found the regular construction S_0 valid (then it is the result,
  /// iterations = 0, and no kernel is computed).
  bool regular_valid = false;
  /// The interior kernel point K (xy or xyz), when the regular construction needed one and its
  /// boundary has a kernel.
  std::optional<std::array<double, P>> kernel;
  double kernel_measure = 0.0;  ///< the kernel's area (P = 2) or volume (P = 3)
  /// Where the result's interior control points were moved: the kernel centroid `kernel`, or a
  /// fitted point (KernelPoint::fitted; then `fitted` is true). Empty when no kernel.
  std::optional<std::array<double, P>> point;
  bool fitted = false;
  /// The width of the Sec. 6 grid the result's interior points were spread over (0: all at
  /// `point`): spread x kernel size, or retry_spread x kernel size when the retry was taken.
  double spread_width = 0.0;
  /// The result meets options.acceptance (or the regular construction was valid).
  bool valid = false;
  /// The result is also strictly valid (geom::check_validity: det J > 0 everywhere).
  bool strictly_valid = false;
  /// Knots per span or degree raisings added (0: S_0 itself, or S_0 with its interior moved).
  /// When not valid: the last iteration tried.
  int iterations = 0;
  /// The result when valid; otherwise the last attempt (S_0 when there was no kernel).
  spline::TensorSpline<P> spline;
  /// Why it failed (empty when valid).
  std::string reason;
};

/// Fadila et al. 2023, Alg. 1 from a given regular construction s0 (any constructor, clamped on its
/// domain), for planar surfaces (xy) and trivariates (xyz).
/// @throws trivox::Error (bad_input) for a rational s0 or too few coordinates
template <int P>
KernelResult<P> kernel_based(const spline::TensorSpline<P>& s0, const KernelConstructOptions& options = {});

/// The regular construction of Fadila et al. 2023 (Alg. 1 line 1) from planar curves (R^k, x y
/// first): boolean_sum [bottom, top, left, right] (S(u,0), S(u,1), S(0,v), S(1,v));
/// half_boolean_sum [c1, c2] with c1(0) = c2(0); ruled [bottom, top] with the ruling at
/// `ruling_order`.
/// @throws trivox::Error (bad_input) for the wrong number of curves or mismatched boundaries
Surface regular_construct(KernelOp op, std::span<const Curve> curves, const KernelConstructOptions& options = {});
/// From surfaces: boolean_sum the six faces u0 u1 v0 v1 w0 w1; half_boolean_sum [s1, s2] or
/// [s1, s2, s3]; ruled [s0, s1].
Trivariate regular_construct(KernelOp op, std::span<const Surface> surfaces, const KernelConstructOptions& options = {});

/// kernel_based(regular_construct(op, curves)): the kernel-based planar constructors.
KernelResult<2> kernel_construct(KernelOp op, std::span<const Curve> curves, const KernelConstructOptions& options = {});
/// kernel_based(regular_construct(op, surfaces)): the kernel-based trivariate constructors.
KernelResult<3> kernel_construct(KernelOp op, std::span<const Surface> surfaces,
                                 const KernelConstructOptions& options = {});

/// Whether det J of a polynomial planar surface (P = 2, xy) or trivariate (P = 3, xyz) has the
/// sign `orientation` (+1 or -1) or is zero everywhere (Acceptance::nonnegative), by Bezier
/// coefficients and subdivision as in geom::check_validity; undecided counts as false.
template <int P>
bool jacobian_nonnegative(const spline::TensorSpline<P>& s, int orientation, const geom::ValidityOptions& options = {});

}  // namespace trivox::construct
