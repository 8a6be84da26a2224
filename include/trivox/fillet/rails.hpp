/// @file trivox/fillet/rails.hpp
/// @brief Rail curves of a fillet: the Euclidean offset of the intersection curve C on a primary
/// surface, at a chosen distance, on the side of the face that lies outside the other cell.
///
/// Masalha, Cirillo & Elber 2021, Sec. 1.2: the rail C_i^r is the curve on S_i at
/// Euclidean distance d_i from C (after Elber & Kim 2020). Found as in Eager &
/// Dannenhoffer 2019 (Flends), Sec. II.B: from each point of C, small steps on the surface along
/// n x C' (the direction in the tangent plane perpendicular to C; the least-squares (du, dv) of
/// the 3 x 2 system), each pulled back into C's normal plane, until the point is about d away;
/// then Newton on the 2 x 2 system |S(u,v) - C(t)|^2 = d^2, (S(u,v) - C(t)) . C'(t) = 0 puts it
/// exactly in C's normal plane at distance d.
///
/// The points are interpolated (cubic) in the parameter space of S_i with the parameter t of C
/// (chord length of C's points, t in [0, 1]). Every interval between samples is checked at 1/4,
/// 1/2 and 3/4 and halved, with a new true intersection point (Newton onto both faces) and new
/// rail points, until all four curves are within the tolerance there.
///
/// Side rule: at each sample the offset direction on face i is +-(n_i x C'); the sign is the one
/// with a positive dot product against the other face's outward normal outward[j] (S_u x S_v),
/// decided once from all samples (they must agree), then reversed by RailOptions::flip[i].
///
/// Self-crossings (a distance larger than C's radius of curvature on the face: the offset has a
/// swallowtail) are detected on the rail's linearised segments in (u, v) and refined by Newton on
/// rail(ta) = rail(tb) (Flends Sec. II.B). The loop between the crossing parameters is trimmed:
/// the rail stays at the crossing point over [ta, tb] (on a closed curve the shorter way round,
/// which may be [0, ta] and [tb, 1]), so the ruled sub-region between C and the rail remains a
/// fan without folds. The widest loop goes first, then the rest is searched again (at most 16 per
/// rail). ta and tb become C0 joins of the common function space (knots of multiplicity 3), so
/// the trimmed stretch is exactly constant.
///
/// Cost: samples * (about 8 marching steps + a few Newton steps) surface evaluations, one banded
/// interpolation per densification round, O(samples^2) box tests per self-crossing search; a few
/// milliseconds for a few hundred samples.
///
/// Limits: the untrimmed offset must stay on the face (a loop is traced before it is cut);
/// leaving the face is detected at the samples and along the marching, not between samples;
/// crossings between rails of different curves, and of a rail with C, are not looked for.
#pragma once
#include <array>
#include <vector>

#include "trivox/geom/surface_intersection.hpp"
#include "trivox/spline/tensor_spline.hpp"

namespace trivox::fillet {

struct RailOptions {
  /// How close each rail is to the exact offset (absolute, model units): distance to C within
  /// tolerance of d, and in C's normal plane within tolerance; also how close the base curves
  /// are to C (|S_1(base_1(t)) - S_2(base_2(t))|), and how far outside its face's parameter
  /// rectangle a rail point may fall by rounding (it is then clamped onto the edge). > 0.
  double tolerance = 1e-7;
  /// flip[i]: put rail i on the other side of C (inside the other cell) instead.
  std::array<bool, 2> flip{false, false};
};

/// A rail with the intersection curve it offsets, both in the face's parameter space.
struct Rail {
  spline::Curve base;  ///< c_I^{S_i}(t): C in the face's parameters (R^2)
  spline::Curve rail;  ///< c_i^r(t): the rail in the face's parameters (R^2)
  /// Parameter intervals [t0, t1] where a self-crossing was trimmed (the rail
  /// is constant there), sorted.
  std::vector<std::array<double, 2>> trimmed;
  /// Largest deviation found when checking between samples: | |S(rail(t)) - C(t)| - d |,
  /// |(S(rail(t)) - C(t)) . T(t)| (C(t) the mean of S_1(base_1(t)) and S_2(base_2(t)), T the unit
  /// n_1 x n_2 there; not on trimmed stretches) and |S_1(base_1(t)) - S_2(base_2(t))|; at most
  /// the tolerance.
  double max_error = 0.0;
};

/// Both rails of one intersection curve. All four curves (rails[0].base, rails[0].rail,
/// rails[1].base, rails[1].rail) share one parameter t in [0, 1] and one function space (order
/// 4, the same clamped knots; interior knots of multiplicity 3 at the trimmed ends of either
/// rail), so that the ruled surfaces (1 - s) base(t) + s rail(t) are tensor-product splines
/// (Masalha et al. 2021, Eq. 3) and S_1(rails[0].base(t)) = S_2(rails[1].base(t)) = C(t) at the
/// same t (to the tolerance).
struct RailPair {
  std::array<Rail, 2> rails;
  bool closed = false;  ///< C, and so all four curves, are closed loops (value at t = 0 equals t = 1)
};

/// The rails on face1 and face2 at distances d[0], d[1] from their intersection curve.
/// Rail i lies on the part of face i that is outside the other cell: its offset direction d
/// has d . n_other > 0, where n_other is the other face's outward normal.
/// @param face1, face2  the primary surfaces S_1, S_2 (coordinates 0..2 are xyz; more ignored)
/// @param outward       outward[i] = +1 when face i's normal S_u x S_v points out of its cell,
///                      -1 when it points in (other values: bad_input)
/// @param curve         an intersection curve from intersect_surfaces(face1, face2)
/// @param distance      d_1, d_2 > 0, model units
/// @throws Error (bad_input) for a distance <= 0 or larger than the face allows: a rail that
///         leaves its face's parameter rectangle (the message names the face 1 or 2, t, C(t) and
///         the (u, v) where it crosses the boundary), or a face that in C's normal plane never
///         gets d away from C(t) (named the same way); a curve with fewer than two distinct
///         points; a tolerance <= 0
/// @throws Error (failed) when a rail point cannot be found (Newton does not converge), the side
///         cannot be decided (the faces are tangent along C, or the sides disagree between
///         samples: a tangential contact between them), or densification does not reach the
///         tolerance
RailPair offset_rails(const spline::Surface& face1, const spline::Surface& face2,
                      std::array<double, 2> outward, const geom::IntersectionCurve& curve,
                      std::array<double, 2> distance, const RailOptions& options = {});

}  // namespace trivox::fillet
