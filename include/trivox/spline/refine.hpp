/// @file trivox/spline/refine.hpp
/// @brief Operations that change a spline's representation but not the function it defines:
/// knot insertion and refinement, degree elevation, clamping, Bezier extraction, splitting,
/// restriction, reparametrisation, reversal and swapping of directions.
///
/// Each is a one-dimensional linear map on the control polygon applied along one direction of
/// the control net (rational splines in homogeneous coordinates). Knot insertion is Boehm's
/// algorithm (NURBS Book A5.1); degree elevation brings every distinct knot's multiplicity up by
/// one and solves for the new coefficients by collocation, exact up to rounding because the old
/// function lies in the new space. Cost: O(n_d * m_d) per line of the net along d.
#pragma once
#include <span>
#include <utility>
#include <vector>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::spline {

/// Inserts knot value t (inside the domain of direction dir) `times` times.
/// @throws Error when t is outside the domain or the multiplicity would exceed the order
template <int P>
TensorSpline<P> insert_knot(const TensorSpline<P>& s, int dir, double t, int times = 1);

/// Inserts many knot values in direction dir (any order, repeats allowed).
template <int P>
TensorSpline<P> refine(const TensorSpline<P>& s, int dir, std::span<const double> knots);

/// Inserts `per_span` uniformly spaced knots in every non-empty span of direction dir.
template <int P>
TensorSpline<P> refine_uniform(const TensorSpline<P>& s, int dir, int per_span = 1);

/// Raises the order of direction dir by `by` (every distinct knot gains `by` multiplicity, so the
/// continuity is kept). The result is clamped.
template <int P>
TensorSpline<P> elevate(const TensorSpline<P>& s, int dir, int by = 1);

/// The same function on a clamped knot vector in direction dir (end knots of multiplicity order).
template <int P>
TensorSpline<P> clamp(const TensorSpline<P>& s, int dir);
/// clamp() in every direction.
template <int P>
TensorSpline<P> clamp(const TensorSpline<P>& s);

/// Bezier form: every knot of direction dir raised to multiplicity order (then each span's
/// control points are its Bezier points).
template <int P>
TensorSpline<P> to_bezier_form(const TensorSpline<P>& s, int dir);
/// to_bezier_form in every direction; a polynomial net goes through the P maps once (the
/// same floats as direction by direction, without a copy of the net per direction).
template <int P>
TensorSpline<P> to_bezier_form(const TensorSpline<P>& s);

/// The Bezier elements of s, one per non-empty tensor span (u fastest, then v, then w), each on
/// its own sub-domain with Bezier knot vectors.
template <int P>
std::vector<TensorSpline<P>> bezier_pieces(const TensorSpline<P>& s);

/// Splits direction dir at t (strictly inside the domain): the parts on [front, t] and [t, back].
template <int P>
std::pair<TensorSpline<P>, TensorSpline<P>> split(const TensorSpline<P>& s, int dir, double t);

/// The restriction of direction dir to [a, b], front <= a < b <= back.
template <int P>
TensorSpline<P> restrict_to(const TensorSpline<P>& s, int dir, double a, double b);

/// The same spline with direction dir's domain mapped affinely onto [a, b] (a < b).
template <int P>
TensorSpline<P> reparametrize(const TensorSpline<P>& s, int dir, double a, double b);

/// The same point set with direction dir traversed backwards: s'(.., t, ..) = s(.., front + back - t, ..).
template <int P>
TensorSpline<P> reverse(const TensorSpline<P>& s, int dir);

/// Directions d1 and d2 exchanged: s'(.., t_d1, .., t_d2, ..) = s(.., t_d2, .., t_d1, ..).
template <int P>
TensorSpline<P> swap_directions(const TensorSpline<P>& s, int d1, int d2);

/// Brings both splines into one function space per direction (the union of their knots at the
/// higher order), so their control nets can be combined point by point.
/// @throws Error when the domains differ
template <int P>
std::pair<TensorSpline<P>, TensorSpline<P>> make_compatible(const TensorSpline<P>& a, const TensorSpline<P>& b);

/// The same function in the space of `target` (direction dir), which must contain it.
template <int P>
TensorSpline<P> to_space(const TensorSpline<P>& s, int dir, const KnotVector& target);

}  // namespace trivox::spline
