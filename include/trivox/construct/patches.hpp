/// @file trivox/construct/patches.hpp
/// @brief Surfaces made from other surfaces, as the shells and solids of a scene need them: a grid
/// of patches merged into one B-spline surface, and the offset of a surface along its normals.
///
/// Merging: patches P_ij (i along u, j along v, each clamped) that meet edge to edge become one
/// surface on [0, n_u] x [0, n_v], patch ij on [i, i+1] x [j, j+1], with the knots of the patches'
/// interiors and each joint of multiplicity order - 1 (C0 there at least, which any two patches
/// sharing an edge allow). The merged surface equals every patch exactly on its square: the
/// control points are the patches', the shared edge rows kept once. So the Utah teapot's body
/// (twelve bicubic Beziers) becomes one face, which the fillets need (fillet::fillet_faces works
/// per pair of faces and fits its sub-regions across knot lines).
///
/// Offset: O(u, v) ~ S(u, v) + d n(u, v), n = S_u x S_v / |S_u x S_v| (the sign of d is that of
/// S_u x S_v), interpolated at the Greville points of S's own space, the knot spans where the
/// deviation |O - (S + d n)| on a dense sample (3 x 3 points inside every span of the result)
/// exceeds the tolerance halved (in u and v separately) until it is within the tolerance
/// everywhere. Refinement is local because the offset is hard only where S's radius of curvature
/// is small against d (the teapot's foot: 0.17 mm against a 2 mm wall). Where |d| is below the radius of curvature on the side the
/// offset goes to, S + d n is at distance exactly |d| from S, so O's distance to S is |d| within
/// the tolerance. Properties (coordinates 3..) are carried along unchanged.
///
/// Cost: merging is a copy; an offset is one tensor interpolation (O(n (k_u + k_v))) per round
/// and a sample of 9 evaluations with first derivatives per span.
#pragma once
#include <span>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::construct {

struct MergeReport {
  double max_gap = 0.0;   ///< the largest distance between control points of shared edges
};

/// The patches of a grid, row after row, merged into one surface.
/// @param patches     rows * columns surfaces of one dimension, row-major: patches[i + columns * j]
///                    is patch (i, j), i along u, j along v; each clamped, polynomial
/// @param columns     patches per row (>= 1)
/// @param tolerance   how far shared edges' control points may be apart (absolute, model units,
///                    over all coordinates)
/// @throws Error (bad_input) naming the patches (by grid position) when sizes, orders or the
///         knots along a shared edge differ, or an edge gap exceeds the tolerance
spline::Surface merge_patches(std::span<const spline::Surface> patches, int columns, double tolerance,
                              MergeReport* report = nullptr);

struct OffsetOptions {
  double tolerance = 1e-3;   ///< largest |O - (S + d n)| (absolute, model units), > 0
  int max_refinements = 8;   ///< rounds of halving the failing knot spans, at most
};

struct OffsetReport {
  double max_error = 0.0;    ///< largest |O - (S + d n)| on the sample
  int refinements = 0;       ///< rounds of halving applied
  int samples = 0;           ///< sample points of the last check
};

/// The offset of s by `distance` along its unit normal S_u x S_v / |S_u x S_v|.
/// @throws Error (bad_input) for a rational or non-3D surface, a distance of 0 or a singular
///         point (S_u x S_v = 0: a collapsed edge has no normal); Error (failed) when the
///         tolerance is not reached within max_refinements
spline::Surface offset_surface(const spline::Surface& s, double distance, const OffsetOptions& options = {},
                               OffsetReport* report = nullptr);

}  // namespace trivox::construct
