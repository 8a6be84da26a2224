/// @file trivox/geom/planar_crossing.hpp
/// @brief Whether planar curves cross one another or themselves: the input check of the planar
/// constructors (Fadila et al. 2023, Sec. 4 assumes boundaries that are "intersection and
/// self-intersection free").
///
/// Each curve (coordinates 0..1) is flattened into a polyline whose chords stay within
/// `tolerance` of it (Bezier pieces subdivided until their control polygons are that flat), and
/// the segments are tested pairwise for proper crossings. Contacts at endpoints that the curves
/// share (a corner of the boundary loop) are allowed; a crossing there is still found when the
/// curves meet again away from it. Sound up to the tolerance: a crossing reported is within
/// `tolerance` of a true crossing or contact; curves that stay farther apart than `tolerance` are
/// never reported.
///
/// Cost: O(S^2) segment tests for S segments in all (S grows like 1/sqrt(tolerance) per curved
/// piece).
#pragma once
#include <array>
#include <optional>
#include <span>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::geom {

struct PlanarCrossing {
  int curve_a = -1, curve_b = -1;  ///< indices into the input (equal: a self-intersection)
  double t_a = 0.0, t_b = 0.0;     ///< approximate parameters on each curve
  std::array<double, 2> point{};   ///< approximate crossing point
};

/// The first crossing found, in a deterministic order (curve pairs in index order), or none.
/// @param tolerance  absolute flatness of the polylines (model units), > 0
std::optional<PlanarCrossing> first_crossing(std::span<const spline::Curve> curves, double tolerance);

}  // namespace trivox::geom
