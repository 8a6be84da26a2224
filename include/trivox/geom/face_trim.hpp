/// @file trivox/geom/face_trim.hpp
/// @brief The kept part of a face cut by curves in its parameter space, as trimmed surfaces.
///
/// A face S(u, v) (xyz, then any properties) is cut by planar curves in its parameter rectangle:
/// closed curves, and open curves whose ends lie on the rectangle's boundary or on other curves
/// (as geom::intersect_surfaces returns its branches in uv1 / uv2; where a face meets several
/// faces of other cells, the curves meet at those cells' edges, end to end or an end on another
/// curve's interior, and they may cross). The curves and the rectangle's boundary form a planar
/// arrangement; trim_face builds it, classifies each of its faces (regions) by the caller's
/// predicate at one interior point of the region (the point of a grid farthest from every curve
/// and from the boundary), and returns every kept region as its own geom::TrimmedSurface: outer
/// loop counter-clockwise, holes clockwise.
///
/// The arrangement (polylines for its topology, the curves themselves for its geometry):
///  1. curves lying along a side of the rectangle, and curves covered by another one (the same
///     intersection found from two cells' shared face), are set aside;
///  2. vertices: the rectangle's corners, the curves' ends, an open curve's end lying on another
///     curve (a junction: the end is projected onto that curve by Newton), and crossings (polyline
///     segments within the tolerance, refined by Newton on the two curves); events within the
///     tolerance of one another are one vertex;
///  3. edges: each curve split at its vertices (spline::restrict_to, exact), the boundary split
///     into straight pieces between its vertices;
///  4. faces: half-edges walked turning at every vertex to the next half-edge clockwise from the
///     reverse of the incoming one (the face on the left), so bounded faces are counter-clockwise
///     cycles; an edge with one face on both sides (separating nothing) is dropped; the clockwise
///     cycle of a component apart from the boundary (an island) is a hole of the smallest region
///     of another component around it.
///
/// Adjacent kept regions are NOT merged: each is returned separately (their areas add up).
///
/// Cost: polylines of at most 16 points per knot span of each curve (capped at 4096 per curve,
/// refused beyond 200,000 segments in all), held in a uniform grid of buckets; crossings tested
/// once per pair of segments sharing a bucket (refused beyond 5e7 pairs or 1e5 meeting points),
/// each refined by a few Newton steps; the interior points test G^2 grid points (G = 32, doubled up to 256 while a region
/// has no grid point) against the regions' polygons and the S segments. Refused beyond
/// FaceTrimOptions::max_curves.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "trivox/geom/trimmed_surface.hpp"
#include "trivox/spline/tensor_spline.hpp"

namespace trivox::geom {

/// True where a point of space (xyz, 3 values) lies in the kept region.
using KeepPredicate = std::function<bool(const double* xyz)>;

struct FaceTrimOptions {
  /// Relative to the parameter rectangle's larger side (> 0, < 1e-3): how far an open curve's
  /// end may lie from the boundary and a closed curve's end from its start.
  double tolerance = 1e-9;
  /// Names the face in error messages ("cell 2, face u-").
  std::string face_name = "face";
  /// Refuse more cutting curves than this.
  int max_curves = 1000;
};

/// One region of the arrangement with its classification, for diagnostics and tests.
struct FaceRegion {
  TrimmedSurface surface;
  double u = 0, v = 0;  ///< the interior point at which the predicate was evaluated
  bool kept = false;
};

/// Every region of the arrangement, in a deterministic order: by the first edge of its outer
/// loop, the boundary's pieces counter-clockwise from (u_min, v_min) first (so the regions
/// touching the boundary come first, in that order), then the curves' pieces in input order
/// and along each curve (so an island's inside follows, in the order of its curves).
/// @throws trivox::Error (bad_input), naming options.face_name, for a rational or non-planar
///         curve, a curve leaving the rectangle, an open curve whose end lies off the boundary
///         and meets no other curve (a dangling end), curves that touch or overlap without
///         crossing, meeting points that the tolerance cannot tell apart, a closed curve
///         enclosing no area, more curves than max_curves or polyline segments than 200,000, or
///         a region too thin to hold an interior point
std::vector<FaceRegion> face_regions(const spline::Surface& face,
                                     const std::vector<spline::Curve>& cuts,
                                     const KeepPredicate& keep, const FaceTrimOptions& options = {});

/// The kept regions of face_regions, each as its own trimmed surface (same order).
std::vector<TrimmedSurface> trim_face(const spline::Surface& face,
                                      const std::vector<spline::Curve>& cuts,
                                      const KeepPredicate& keep,
                                      const FaceTrimOptions& options = {});

}  // namespace trivox::geom
