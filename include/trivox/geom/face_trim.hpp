/// @file trivox/geom/face_trim.hpp
/// @brief The kept part of a face cut by curves in its parameter space, as trimmed surfaces.
///
/// A face S(u, v) (xyz, then any properties) is cut by planar curves in its parameter rectangle:
/// closed curves, or open curves whose two ends lie on the rectangle's boundary (as
/// geom::intersect_surfaces returns its branches in uv1 / uv2). The rectangle's boundary and the
/// curves form a planar arrangement; trim_face traces its regions, classifies each by the
/// caller's predicate at one interior point of the region (the point of a grid farthest from
/// every curve and from the boundary), and returns every kept region as its own
/// geom::TrimmedSurface: outer loop counter-clockwise, holes clockwise.
///
/// Open curves whose ends meet off the boundary (within the tolerance) are first joined end to
/// end into chains (the intersections of a face with the several faces of another cell meet at
/// that cell's edges), in input order; a chain that returns to its start is a closed curve.
///
/// Regions are traced as follows. Open curves are chords: walking the boundary
/// counter-clockwise from a chord's end to the next chord end, then along that chord to its
/// other end, and on, encloses one region on the left. Closed curves are islands: each bounds
/// the region inside it (minus the closed curves directly inside it), and is a hole of the
/// region that directly contains it.
///
/// Adjacent kept regions are NOT merged: each is returned separately (their areas add up).
/// Curves must not cross one another or themselves (refused, checked on polylines); curves
/// that only meet on the boundary are accepted.
///
/// Cost: polylines of at most 16 points per knot span of each curve (capped at 4096 per
/// curve); the crossing check is O(S^2) in the S polyline segments; the interior points test
/// G^2 grid points (G = 32, doubled up to 256 while a region has no grid point) against all S
/// segments. Refused beyond FaceTrimOptions::max_curves.
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

/// Every region of the arrangement, in a deterministic order: first the regions bounded by
/// the rectangle's boundary (traced from the boundary point of smallest perimeter position,
/// counter-clockwise from (u_min, v_min)), then the inside of each closed curve in input order.
/// @throws trivox::Error (bad_input), naming options.face_name, for a rational or non-planar
///         curve, an open curve (chain) whose end lies off the boundary and meets no other curve's end, curves crossing, more curves
///         than max_curves, or a region too thin to hold an interior point
std::vector<FaceRegion> face_regions(const spline::Surface& face,
                                     const std::vector<spline::Curve>& cuts,
                                     const KeepPredicate& keep, const FaceTrimOptions& options = {});

/// The kept regions of face_regions, each as its own trimmed surface (same order).
std::vector<TrimmedSurface> trim_face(const spline::Surface& face,
                                      const std::vector<spline::Curve>& cuts,
                                      const KeepPredicate& keep,
                                      const FaceTrimOptions& options = {});

}  // namespace trivox::geom
