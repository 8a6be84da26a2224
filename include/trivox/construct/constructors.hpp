/// @file trivox/construct/constructors.hpp
/// @brief The classical constructors of surfaces from curves and of trivariates from surfaces:
/// extrusion, ruling, revolution, Boolean sum, half Boolean sum and sweep (interpolation through
/// a sequence of sections). Control points live in R^k, any k >= 1: coordinates 0..2 are xyz
/// (0..1 for planar input) and the rest are properties, which ride along linearly.
///
/// Massarwi & Elber 2016, Sec. 3.2.2: extruded volume T = S + V w, ruled volume
/// T = (1 - w) S_1 + w S_2, volume of revolution, volumetric Boolean sum of six surfaces, sweep
/// through surfaces S_i at w_i. Fadila, Hong & Elber, Sec. 3: half Boolean sums
/// S = C_1(u) + C_2(v) - P (Sec. 3.1), T = S_1(u,v) + S_2(u,w) - C(u) and
/// T = S_1(u,v) + S_2(v,w) + S_3(u,w) - (C_1(u) + C_2(v) + C_3(w)) + P (Sec. 3.2). The Boolean
/// sum is the Coons construction (Elber, Kim & Kim 2012, as the papers use it): the sum of the
/// linear blends between opposite boundaries, less the blends of the shared edges, plus the
/// corner blend.
///
/// Conventions. Every constructor first brings its inputs into common function spaces (clamping,
/// reparametrising each direction to [0, 1], degree elevation and knot refinement), so the result
/// is a clamped spline on [0, 1]^P. A new direction (the ruling, the extrusion, the sweep) comes
/// last: a surface's v, a trivariate's w. Results are polynomial unless an input is rational
/// (only extrusion and ruling accept rational input). Boundaries that must coincide are checked
/// against `tolerance` (absolute, in model units, over the first `geometry_coords` coordinates):
/// a mismatch throws trivox::Error (bad_input) naming the two boundaries and the distance.
///
/// Cost: the size of the result times the number of terms summed (at most 7), plus the degree
/// elevations and refinements to the common spaces (O(n * order) per control line).
#pragma once
#include <array>
#include <span>
#include <vector>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::construct {

using spline::Curve;
using spline::Surface;
using spline::Trivariate;

/// How far apart boundaries that must coincide may be (model units, over the geometric
/// coordinates only: properties may jump between inputs and are then averaged).
struct MatchOptions {
  double tolerance = 1e-9;
  /// Coordinates 0..geometry_coords-1 are compared; -1: min(3, dim).
  int geometry_coords = -1;
};

// ---------------------------------------------------------------------------------------------
// Building blocks

/// The same spline, clamped and with every direction's domain mapped onto [0, 1].
template <int P>
spline::TensorSpline<P> normalized(const spline::TensorSpline<P>& s);

/// Splines brought into one function space per direction (the union of their knots at the
/// highest order), each first normalized(): their control nets can be combined point by point.
/// @throws Error (bad_input) when the splines' coordinate counts differ or any is rational
template <int P>
std::vector<spline::TensorSpline<P>> common_space(std::span<const spline::TensorSpline<P>> splines);

/// Stacks n splines of P-1 parameters, all in one function space, as the control rows of a new
/// direction `dir` (0..P-1) with knot vector `knots` (knots.size() == n):
/// result(.., t_dir, ..) = sum_i N_i(t_dir) layers[i](..).
/// @throws Error (bad_input) when the layers' spaces or dims differ or the count does not match
template <int P>
spline::TensorSpline<P> stack(std::span<const spline::TensorSpline<P - 1>> layers, int dir,
                              const spline::KnotVector& knots);

/// The spline constant along a new direction `dir`: r(.., t_dir, ..) = s(..), order 1 would be
/// enough but order 2 with two equal rows is used (a clamped Bezier line on [0, 1]).
template <int P>
spline::TensorSpline<P> extend_constant(const spline::TensorSpline<P - 1>& s, int dir);

// ---------------------------------------------------------------------------------------------
// Extrusion and ruling

/// Ruled surface S(u, v) = (1 - v) bottom(u) + v top(u) (Massarwi & Elber 2016, Sec. 3.2.2 item 2,
/// one dimension down). `ruling_order` >= 2 raises the ruling direction by degree elevation (the
/// same surface; Fadila et al. 2023, Sec. 5.1 starts the kernel-based ruling at order 3).
Surface ruled(const Curve& bottom, const Curve& top, int ruling_order = 2);
/// Ruled volume T(u, v, w) = (1 - w) s0(u, v) + w s1(u, v) (Massarwi & Elber
/// 2016, Sec. 3.2.2 item 2).
Trivariate ruled(const Surface& s0, const Surface& s1, int ruling_order = 2);

/// Extruded surface S(u, v) = C(u) + V v, v in [0, 1]. `vector` has 1..dim entries; missing
/// ones (the properties) are 0.
Surface extrude(const Curve& c, std::span<const double> vector);
/// Extruded volume T(u, v, w) = S(u, v) + V w (Massarwi & Elber 2016, Sec. 3.2.2 item 1).
Trivariate extrude(const Surface& s, std::span<const double> vector);

// ---------------------------------------------------------------------------------------------
// Revolution

/// The axis and sweep angle of a revolution, and how closely the polynomial result follows the
/// exact rotation.
struct Revolution {
  std::array<double, 3> origin{0, 0, 0};
  std::array<double, 3> axis{0, 0, 1};   ///< any non-zero length
  double angle = 6.283185307179586;      ///< radians, (0, 2 pi], right-handed about `axis`
  /// Largest distance between the result and the exact rotation of the input, relative to the
  /// input's largest distance from the axis (so the result does not depend on units).
  double relative_tolerance = 1e-6;
  int order = 4;                          ///< order of the revolution direction (>= 3)
};

/// Surface of revolution of a curve in R^k (k >= 3): S(u, v) = the point C(u) rotated by
/// v * angle about the axis, properties unchanged. Polynomial: the rotation's (cos, sin) is a
/// uniform B-spline interpolant of the unit circle arc with enough segments for the tolerance,
/// and S's control points are A + c_j R + s_j (a x R) for each of C's control points (A its
/// projection on the axis, R the radial vector), which is exact up to that interpolant because
/// the rotation is linear in the point. Massarwi & Elber 2016, Sec. 3.2.2 item 3.
/// @throws Error (bad_input) on a zero axis, an angle out of range, a tolerance <= 0, or an
///         input with fewer than 3 coordinates or rational
Surface revolve(const Curve& c, const Revolution& r);
/// Volume of revolution of a surface (Massarwi & Elber 2016, Sec. 3.2.2 item 3).
Trivariate revolve(const Surface& s, const Revolution& r);

/// The polynomial unit-circle arc used by revolve: a planar clamped curve on [0, 1] with
/// |C(t) - (cos(t angle), sin(t angle))| <= tolerance for every t (checked on a dense sample
/// with a margin). @param order >= 3
Curve circle_arc(double angle, double tolerance, int order = 4);

// ---------------------------------------------------------------------------------------------
// Boolean sums

/// Boolean sum (Coons) surface from its four boundaries: bottom = S(u, 0), top = S(u, 1),
/// left = S(0, v), right = S(1, v); the corners must coincide (bottom(0) = left(0),
/// bottom(1) = right(0), top(0) = left(1), top(1) = right(1)).
Surface boolean_sum(const Curve& bottom, const Curve& top, const Curve& left, const Curve& right,
                    const MatchOptions& match = {});

/// Volumetric Boolean sum from six faces in the order and parametrisation of the model format's
/// face names: faces[0..5] = T(0, v, w), T(1, v, w), T(u, 0, w), T(u, 1, w), T(u, v, 0),
/// T(u, v, 1) (u0 u1 v0 v1 w0 w1; each face's parameters are the two other directions in
/// increasing order). The twelve shared edges must coincide.
Trivariate boolean_sum(std::span<const Surface> faces, const MatchOptions& match = {});

/// Half Boolean sum surface S(u, v) = c1(u) + c2(v) - c1(0), c1(0) = c2(0) (Fadila et al. 2023,
/// Sec. 3.1, Lemma 1: S(u, 0) = c1(u), S(0, v) = c2(v)).
Surface half_boolean_sum(const Curve& c1, const Curve& c2, const MatchOptions& match = {});

/// Half Boolean sum trivariate of two surfaces sharing C(u) = s1(u, 0) = s2(u, 0):
/// T(u, v, w) = s1(u, v) + s2(u, w) - C(u) (Fadila et al. 2023, Sec. 3.2, Lemma 2: T(u, v, 0) = s1,
/// T(u, 0, w) = s2).
Trivariate half_boolean_sum(const Surface& s1, const Surface& s2, const MatchOptions& match = {});

/// Half Boolean sum trivariate of three surfaces s1(u, v), s2(v, w), s3(u, w) sharing
/// C1(u) = s1(u, 0) = s3(u, 0), C2(v) = s1(0, v) = s2(v, 0), C3(w) = s2(0, w) = s3(0, w) and the
/// corner P: T = s1 + s2 + s3 - (C1 + C2 + C3) + P (Fadila et al. 2023, Sec. 3.2, Lemma 3: T(u, v,
/// 0) = s1, T(0, v, w) = s2, T(u, 0, w) = s3).
Trivariate half_boolean_sum(const Surface& s1, const Surface& s2, const Surface& s3,
                            const MatchOptions& match = {});

// ---------------------------------------------------------------------------------------------
// Sweep through sections

/// The surface through curves C_i at parameters v_i: S(u, v_i) = C_i(u), i = 0..n-1 (n >= 2),
/// interpolating in v with order min(order, n). `params` empty: chord-length parameters from
/// the sections' control points (NURBS Book eq. 9.5), normalised to [0, 1]; else n strictly
/// increasing values, mapped onto [0, 1].
Surface sweep(std::span<const Curve> sections, std::span<const double> params = {}, int order = 4);
/// The trivariate through surfaces S_i at w_i: T(u, v, w_i) = S_i(u, v) (Massarwi & Elber 2016,
/// Sec. 3.2.2 item 5, volumetric sweep by interpolation).
Trivariate sweep(std::span<const Surface> sections, std::span<const double> params = {},
                 int order = 4);

/// The parameters at which sweep() placed its sections (for tests and reports).
template <int P>
std::vector<double> sweep_params(std::span<const spline::TensorSpline<P - 1>> sections,
                                 std::span<const double> params = {});

}  // namespace trivox::construct
