/// @file trivox/geom/closest_point.hpp
/// @brief The point of a surface closest to a given point, and so the distance from a point to a
/// set of surfaces (the boundary of a V-model).
///
/// Massarwi & Elber 2016, Sec. 5.2, Eq. 3 with C(t) = P: the closest point is where
/// <P - S(u,v), S_u> = <P - S(u,v), S_v> = 0, or on the domain's boundary. Solved here
/// numerically rather than by a subdivision solver: a precomputed grid of samples (a few per
/// knot span and direction) picks the start, then Newton on the gradient of |S - P|^2 / 2 (with
/// the full Hessian from second partials), projected onto the parameter rectangle (a coordinate
/// at a bound whose step leaves the domain is frozen), damped so the distance never grows. For
/// a start near the global minimum this converges quadratically; the sample grid makes a wrong
/// basin unlikely for the smooth, gently curved faces of cells, not impossible for a surface
/// that folds back within one grid spacing.
///
/// Warm starts (closest(p, start)): Newton from a given (u,v), typically the answer at a nearby
/// point, skipping the sample pass. It converges to the local minimum whose basin holds the start:
/// the same point as the cold query (to rounding) when both starts lie in the global minimum's
/// basin, which holds for points moving little against the surface's curvature radius; it is not
/// certified. Callers that need start-independent bytes keep the chain of warm starts
/// deterministic (fillet/shepard.hpp: per sampler block, cold at every row start) and check the
/// answer against the 1-Lipschitz bound of the distance (WarmCheck).
///
/// Cost: building: samples_per_span^2 * spans evaluations; a query: one pass over the samples
/// (3 flops each) and a few evaluations with second partials; a warm query: the evaluations only
/// (two or three Newton steps for a start one voxel away).
#pragma once
#include <array>
#include <vector>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::geom {

struct ClosestPoint {
  std::array<double, 2> uv{};      ///< parameters of the closest point
  std::array<double, 3> point{};   ///< S(uv), xyz
  double distance = 0.0;           ///< |S(uv) - P|
  /// Newton ended at a stationary point (step below 1e-15 of the domain, below 1e-12
  /// and no longer shrinking, or no descent left);
  /// false when it ran out of iterations.
  bool converged = true;
};

/// A surface prepared for closest-point queries (xyz: coordinates 0..2).
class SurfaceDistance {
public:
  /// @param samples_per_span  samples along each direction per knot span (>= 2)
  /// @throws trivox::Error (bad_input) for fewer than 3 coordinates
  explicit SurfaceDistance(spline::Surface surface, int samples_per_span = 6);

  /// The closest point to p. Thread-safe.
  ClosestPoint closest(const std::array<double, 3>& p) const;

  /// The local minimum of |S - p| reached by damped, projected Newton from `start` (clamped to
  /// the domain) alone: no sample pass (see the file comment on warm starts). Thread-safe.
  /// @param values  when not null: the surface's dim() coordinates at the answer (xyz and any
  ///                properties it carries), from the evaluation that gives `point`
  ClosestPoint closest(const std::array<double, 3>& p, const std::array<double, 2>& start,
                       double* values = nullptr) const;

  const spline::Surface& surface() const noexcept { return surface_; }

private:
  /// Newton from t (with |S(t) - p|^2 = f) to a stationary point; returns converged.
  /// buf: 18 values, val: 3.
  bool descend(const std::array<double, 3>& p, std::array<double, 2>& t, double& f, double* buf, double* val) const;

  spline::Surface surface_;
  spline::Surface geo_;                     ///< its xyz alone (what Newton evaluates)
  std::vector<std::array<double, 2>> uv_;   ///< sample parameters
  std::vector<std::array<double, 3>> xyz_;  ///< sample points
};

/// The smallest distance from p to any of the surfaces (infinity for none).
double distance(const std::vector<SurfaceDistance>& surfaces, const std::array<double, 3>& p);

}  // namespace trivox::geom
