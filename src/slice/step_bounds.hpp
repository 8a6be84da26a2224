/// @file src/slice/step_bounds.hpp
/// @brief (private to src/slice) Bounds on a polynomial Bezier piece's derivatives from the
/// differences of its control points (convex hull property): the hodograph bound on the first
/// partials, which the locator's construction keeps per piece for skipping parts in Newton's
/// subdivision fallback. The second and third partials' bounds (StepBounds) are computed on
/// first use by Locator::step_bounds (step_bounds.cpp).
#pragma once
#include "locator_data.hpp"

namespace trivox::slice::detail {

/// Hodograph bound: |dX/dt_d| <= (order - 1) max |P_{i+1} - P_i| / len (polynomial nets with
/// `stride` coordinates per point, xyz first).
Vec3 hodograph_bounds(const double* net, const Locator::Data::Piece& pc, int stride);

}  // namespace trivox::slice::detail
