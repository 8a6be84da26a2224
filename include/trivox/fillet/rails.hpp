/// @file trivox/fillet/rails.hpp
/// @brief Rail curves of a fillet: the Euclidean offset of the intersection curve C on a primary
/// surface, at a chosen distance, on the side of the face that lies outside the other cell.
///
/// Masalha, Cirillo & Elber 2021 (seed 000), Sec. 1.2: the rail C_i^r is the curve on S_i at
/// Euclidean distance d_i from C (after Elber & Kim 2020). Found as in Eager & Dannenhoffer,
/// Flends (seed 002), Sec. II.B: from each point of C, small steps on the surface along
/// n x C' (the direction in the tangent plane perpendicular to C; the least-squares (du, dv) of
/// the 3 x 2 system), until the point is d away; then Newton on the 2 x 2 system
/// |S(u,v) - C(t)|^2 = d^2, (S(u,v) - C(t)) . C'(t) = 0 puts it exactly in C's normal plane at
/// distance d. The points are interpolated in the parameter space of S_i with the parameter t of
/// C, densified until the curve between samples is within the tolerance. A rail that crosses
/// itself (a distance larger than C's radius of curvature on the face) is detected on its
/// linearised segments and refined by Newton (Flends Sec. II.B); the loop between the crossing
/// parameters is trimmed: the rail stays at the crossing point there, so the ruled sub-region
/// between C and the rail remains a fan without folds.
/// Cost: samples * (distance / step) surface evaluations, plus one interpolation per
/// densification round.
#pragma once
#include <array>
#include <vector>

#include "trivox/geom/surface_intersection.hpp"
#include "trivox/spline/tensor_spline.hpp"

namespace trivox::fillet {

struct RailOptions {
  /// How close each rail is to the exact offset (absolute, model units): distance to C within
  /// tolerance of d, and in C's normal plane within tolerance; also how close the base curves
  /// are to C. > 0.
  double tolerance = 1e-7;
  /// flip[i]: put rail i on the other side of C (inside the other cell) instead.
  std::array<bool, 2> flip{false, false};
};

/// A rail with the intersection curve it offsets, both in the face's parameter space.
struct Rail {
  spline::Curve base;  ///< c_I^{S_i}(t): C in the face's parameters (R^2)
  spline::Curve rail;  ///< c_i^r(t): the rail in the face's parameters (R^2)
  /// Parameter intervals [t0, t1] where a self-crossing was trimmed (the rail is constant there).
  std::vector<std::array<double, 2>> trimmed;
  /// Largest deviation found when checking between samples: | |S(rail(t)) - C(t)| - d | and
  /// |(S(rail(t)) - C(t)) . T(t)| (T the unit tangent of C); at most the tolerance.
  double max_error = 0.0;
};

/// Both rails of one intersection curve. All four curves (rails[0].base, rails[0].rail,
/// rails[1].base, rails[1].rail) share one parameter t in [0, 1] and one function space (same
/// order, same knots), so that the ruled surfaces (1 - s) base(t) + s rail(t) are tensor-
/// product splines (seed 000, Eq. 3) and S_1(rails[0].base(t)) = S_2(rails[1].base(t)) = C(t)
/// at the same t (to the tolerance).
struct RailPair {
  std::array<Rail, 2> rails;
  bool closed = false;  ///< C, and so both rails, are closed loops (value at t = 0 equals t = 1)
};

/// The rails on face1 and face2 at distances d[0], d[1] from their intersection curve.
/// Rail i lies on the part of face i that is outside the other cell: its offset direction d
/// has d . n_other > 0, where n_other is the other face's outward normal.
/// @param face1, face2  the primary surfaces S_1, S_2 (coordinates 0..2 are xyz; more ignored)
/// @param outward       outward[i] = +1 when face i's normal S_u x S_v points out of its cell,
///                      -1 when it points in
/// @param curve         an intersection curve from intersect_surfaces(face1, face2)
/// @param distance      d_1, d_2 > 0, model units
/// @throws Error (bad_input) for a distance <= 0 or larger than the face allows: a rail that
///         leaves its face's parameter rectangle (the message names the face 1 or 2, t and
///         (u, v)), or a curve with fewer than two points
/// @throws Error (failed) when a rail point cannot be found (Newton does not converge), or the
///         side cannot be decided (the faces are tangent along C)
RailPair offset_rails(const spline::Surface& face1, const spline::Surface& face2,
                      std::array<double, 2> outward, const geom::IntersectionCurve& curve,
                      std::array<double, 2> distance, const RailOptions& options = {});

}  // namespace trivox::fillet
