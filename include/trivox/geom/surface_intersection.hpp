/// @file trivox/geom/surface_intersection.hpp
/// @brief The intersection curves of two parametric surfaces in R^3: every component, open or
/// closed, as points on both surfaces and as B-spline curves in xyz and in both parameter spaces.
///
/// What the fillets start from (Masalha, Cirillo & Elber 2021, Masalha et al. 2021, Sec. 1.1: the
/// intersection curve C of the two primary surfaces) and what the Booleans' boundary V-surfaces
/// are trimmed by (Massarwi & Elber 2016, Sec. 4). The method is the classical one of
/// marching with Newton correction (Barnhill & Kersey 1990; Patrikalakis & Maekawa, Shape
/// Interrogation, 2002, Sec. 5.8):
/// 1. Seeds: pairs of Bezier pieces whose control boxes overlap are subdivided (the larger of
///    the two, in its longer direction) until both are small; in each remaining pair, Gauss-
///    Newton on S_1(u,v) - S_2(s,t) = 0 (the minimum-norm step of the 3 x 4 system) from the
///    pair's centres gives a point of the intersection, if one is near.
/// 2. Tracing: from a seed not yet on a traced curve, steps along T = n_1 x n_2: a predictor
///    X + h T, then Newton on the 4 x 4 system S_1 = S_2, (S_1 - X - h T) . T = 0; the step h
///    halves where Newton fails or the tangent turns by more than 10 degrees, and grows back
///    after easy steps. A branch ends where it leaves either parameter rectangle (the crossing is
///    found by bisection on the step) or, for a closed component, where it returns to its start.
/// 3. Curves: cubic interpolation of the points (chord length) in xyz and in each parameter
///    space; the points are densified (at most 6 passes) until, between every two points, the
///    xyz curve's midpoint and both surfaces evaluated at the parameter-space curves' midpoints
///    lie within the tolerance of the intersection point there (the faces are trimmed along the
///    parameter-space curves, so their images must follow the intersection too).
/// Points meet the surfaces to `tolerance` (absolute, model units). Tangential contacts (where
/// n_1 x n_2 vanishes) and coincident regions (coplanar faces) are not curves: they are not
/// traced, and, on request, reported as contacts classified by the surfaces' second-order
/// contact there (point, curve or region; Patrikalakis & Maekawa 2002, Ch. 6). A branch that
/// degenerates to a single point is dropped (see intersect_surfaces). Cost: seeds O(pairs of
/// pieces * subdivisions), tracing O(length / step) Newton solves of a few evaluations each; a
/// contact's classification about 20 small Newton solves.
#pragma once
#include <array>
#include <vector>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::geom {

struct IntersectionPoint {
  std::array<double, 3> xyz{};
  std::array<double, 2> uv1{};  ///< parameters on the first surface
  std::array<double, 2> uv2{};  ///< parameters on the second surface
};

struct IntersectionCurve {
  std::vector<IntersectionPoint> points;  ///< in order along the curve
  bool closed = false;                    ///< the last point joins the first
  spline::Curve xyz;                      ///< through the points, in R^3 (empty: a single point)
  spline::Curve uv1, uv2;                 ///< the same in each parameter space (R^2)
};

/// A place where the surfaces meet without crossing: their normals are parallel at `at`.
struct IntersectionContact {
  enum class Kind {
    point,   ///< they touch at `at` alone (an isolated contact: bounds nothing)
    curve,   ///< they touch along a curve through `at` (tangential contact along a curve)
    region,  ///< they coincide around `at` (coplanar faces, identical patches)
  };
  Kind kind = Kind::point;
  IntersectionPoint at;
};

struct IntersectionOptions {
  double tolerance = 1e-9;   ///< how close points are to both surfaces (model units), > 0
  /// Largest marching step, as a fraction of the larger surface's box diagonal.
  double max_step = 0.02;
};

/// All intersection components of surfaces a and b (coordinates 0..2), in a deterministic order.
/// Every curve returned has at least 2 points and its fitted curves: a branch whose points all
/// lie within 10 tolerances of one another (surfaces meeting at a single point: rectangles
/// touching at a corner, a branch cut short at a pole or other singular point) is dropped, since
/// it bounds no region; a curve through such a point is traced from its other seeds.
/// @param contacts  when not null, receives the tangential contacts met among the seeds (where
///                  n_1 x n_2 vanishes), one per 0.75 marching steps and at most 32, each
///                  classified by the second-order contact of the surfaces there (see the .cpp):
///                  isolated points, curves of tangential contact, coincident regions. Seeds
///                  that Newton does not bring within the tolerance are not seen, so an empty
///                  list does not prove that the surfaces cross transversally everywhere.
/// @throws trivox::Error (bad_input) for surfaces with fewer than 3 coordinates or a tolerance <= 0
std::vector<IntersectionCurve> intersect_surfaces(const spline::Surface& a, const spline::Surface& b,
                                                  const IntersectionOptions& options = {},
                                                  std::vector<IntersectionContact>* contacts = nullptr);

}  // namespace trivox::geom
