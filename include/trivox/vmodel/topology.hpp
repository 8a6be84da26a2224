/// @file trivox/vmodel/topology.hpp
/// @brief The topology of a V-model: half-V-surfaces, V-surfaces, V-curves and V-points, and
/// which cell faces are glued to which.
///
/// Massarwi & Elber 2016, Sec. 3.1, Defs. 3.4-3.9 and Sec. 3.1.1 (gluing). Every
/// boundary face of a cell that has area is a *half-V-surface*; two half-V-surfaces of different
/// cells that coincide geometrically are glued into one interior *V-surface*, and a half-V-surface
/// glued to nothing is a boundary V-surface on its own. The cells' edges, merged where they
/// coincide (in either direction), are the *V-curves*; their corners, merged likewise, the
/// *V-points*. Only xyz (coordinates 0..2) is compared, never the properties.
///
/// Coincidence is tested on geometry, not on control points, so the cells may hold the shared
/// face in different function spaces (other orders, other knots, another parametric domain): two
/// faces coincide when their points on a uniform grid of `samples` x `samples` normalised
/// parameters agree within `tolerance` under one of the 8 orientations of the square (identity,
/// reversals, swap). Faces that agree only after a non-affine reparametrisation are not glued
/// (the paper eliminates those by composition; trivox's constructors do not produce them). A face
/// is degenerate (no surface) when its area, estimated by a midpoint rule on |S_s x S_t|, is
/// below `tolerance` times its extent: a face collapsed to a curve or a point. An edge is
/// degenerate when all its samples lie within `tolerance` of one another.
///
/// Gluing pairs faces greedily, in cell order: a face of a cell is never glued to another face
/// of the same cell (a cell closed onto itself, such as a full ring, keeps both seam faces as
/// boundary V-surfaces), and a third face coinciding with an already glued pair (overlapping
/// cells, not a valid V-model) stays a boundary V-surface of its own.
///
/// Cost: O(cells * (samples^2 + area_samples^2) * prod(order)) evaluations; candidates are found
/// by hashing quantised centroids (expected O(1) per face, edge and corner), so the whole is
/// linear in the number of cells, not quadratic (27,000 trilinear cells: about 4 s on one core).
/// Memory: O(cells * samples^2). Output order is deterministic: entities are numbered in the
/// order of their first appearance, cell by cell.
///
/// Conventions (as in the model format): faces u0 u1 v0 v1 w0 w1 (spline::Face); the face's two
/// parameters (s, t) are the two other directions in increasing order. Corner c = i + 2j + 4k
/// (i, j, k = 0 at the minimum of u, v, w; u fastest). Edge e runs along direction d = e / 4 with
/// the two other directions d1 < d2 at their minimum or maximum: d1 at side (e & 1), d2 at side
/// ((e >> 1) & 1). An edge runs from the corner with bit d clear to the corner with bit d set.
#pragma once
#include <array>
#include <vector>

#include "trivox/spline/extract.hpp"
#include "trivox/vmodel/vmodel.hpp"

namespace trivox::vmodel {

/// How matching is done. Defaults suit models in single precision or better.
struct TopologyOptions {
  /// Largest distance at which two points count as one, relative to the diagonal of the model's
  /// xyz control box (so the result does not depend on units). >= 0.
  double relative_tolerance = 1e-9;
  /// Grid of samples x samples normalised parameters compared per face, samples per edge. >= 2.
  int samples = 5;
  /// Grid of area_samples x area_samples midpoints for the area of a face. >= 1.
  int area_samples = 6;
};

/// The map from one face's normalised parameters (s, t) in [0,1]^2 to the glued face's:
/// (a, b) = swap ? (t, s) : (s, t); then a -> 1 - a if reverse_first, b -> 1 - b if
/// reverse_second. The glued face at (a, b) is the same point as this face at (s, t).
struct Orientation {
  bool swap = false;
  bool reverse_first = false;
  bool reverse_second = false;

  std::array<double, 2> apply(std::array<double, 2> st) const noexcept;
  /// The map back, from the glued face's parameters to this one's.
  Orientation inverse() const noexcept;
  /// 0..7: swap * 4 + reverse_first * 2 + reverse_second.
  int index() const noexcept { return (swap ? 4 : 0) + (reverse_first ? 2 : 0) + (reverse_second ? 1 : 0); }
  static Orientation from_index(int i) noexcept { return {(i & 4) != 0, (i & 2) != 0, (i & 1) != 0}; }

  bool operator==(const Orientation&) const = default;
};

/// A boundary face of one cell that has area (Def. 3.6).
struct HalfVSurface {
  int cell = -1;
  spline::Face face = spline::Face::u0;
  int v_surface = -1;        ///< the V-surface it belongs to
  int twin = -1;             ///< the half-V-surface glued to it, or -1 on the model's boundary
  Orientation to_twin;       ///< this face's (s, t) to the twin's; identity when twin == -1
  std::array<int, 4> v_curves{-1, -1, -1, -1};  ///< its edges s=0, s=1, t=0, t=1 (-1: degenerate)
};

/// An interior V-surface (two half-V-surfaces) or a boundary one (one) (Def. 3.4).
struct VSurface {
  std::array<int, 2> halves{-1, -1};  ///< half-V-surface indices; halves[1] == -1 on the boundary
  bool boundary() const noexcept { return halves[1] < 0; }
};

/// One cell's use of a V-curve.
struct CellEdge {
  int cell = -1;
  int edge = -1;          ///< 0..11, see the file comment
  bool reversed = false;  ///< the edge runs against the V-curve's direction
};

/// A distinct cell edge with length (Def. 3.7).
struct VCurve {
  std::array<int, 2> v_points{-1, -1};  ///< start and end (equal for a closed curve)
  std::vector<CellEdge> uses;           ///< every cell edge that is this curve; uses[0] defines the direction
  std::vector<int> v_surfaces;          ///< the V-surfaces bounded by it, ascending
};

/// One cell's use of a V-point.
struct CellCorner {
  int cell = -1;
  int corner = -1;  ///< 0..7, see the file comment
};

/// A distinct cell corner (Def. 3.8).
struct VPoint {
  std::array<double, 3> position{};  ///< xyz of its first use
  std::vector<CellCorner> uses;
  std::vector<int> v_curves;  ///< the V-curves that start or end here, ascending
};

/// The topology of a V-model: its gluing (Def. 3.9).
struct Topology {
  int v_cells = 0;
  double tolerance = 0.0;  ///< the absolute distance used
  std::vector<HalfVSurface> half_v_surfaces;
  std::vector<VSurface> v_surfaces;
  std::vector<VCurve> v_curves;
  std::vector<VPoint> v_points;
  /// Per cell: half-V-surface of each face (index = spline::Face), -1 for a degenerate face.
  std::vector<std::array<int, 6>> cell_faces;
  /// Per cell: V-curve of each edge, -1 for an edge collapsed to a point.
  std::vector<std::array<int, 12>> cell_edges;
  /// Per cell: V-point of each corner.
  std::vector<std::array<int, 8>> cell_corners;
};

/// The counts `trivox info` reports; field names are the JSON keys.
struct TopologyCounts {
  int v_cells = 0;
  int v_surfaces = 0;
  int half_v_surfaces = 0;
  int v_curves = 0;
  int v_points = 0;

  bool operator==(const TopologyCounts&) const = default;
};

/// One glued pair of faces, seen from `cell`.
struct FaceGlue {
  int cell = -1;
  spline::Face face = spline::Face::u0;
  int neighbour = -1;
  spline::Face neighbour_face = spline::Face::u0;
  Orientation orientation;  ///< face's (s, t) to neighbour_face's
};

/// How two cells touch (the queries of Sec. 3.1): the highest-dimensional shared element.
enum class Contact { none, point, curve, surface };

/// Glues the cells of `model` (Sec. 3.1.1).
/// @param model    cells with at least 3 coordinates; surfaces (NamedSurface) are ignored
/// @param options  tolerances and sample counts, see TopologyOptions
/// @throws trivox::Error (bad_input) for an option out of range or a cell with fewer than 3
///         coordinates, naming it
Topology build_topology(const VModel& model, const TopologyOptions& options = {});

TopologyCounts counts(const Topology& topo) noexcept;

/// Every glued face, once from each side, in the order of (cell, face).
std::vector<FaceGlue> glued_faces(const Topology& topo);

/// The cells sharing a V-surface with `cell`, ascending, each once.
/// @throws trivox::Error when cell is not a cell index of topo
std::vector<int> neighbours(const Topology& topo, int cell);

/// The cells having `v_curve` as an edge, ascending, each once.
/// @throws trivox::Error when v_curve is not a V-curve index of topo
std::vector<int> cells_around_curve(const Topology& topo, int v_curve);

/// The cells having `v_point` as a corner, ascending, each once.
/// @throws trivox::Error when v_point is not a V-point index of topo
std::vector<int> cells_around_point(const Topology& topo, int v_point);

/// Whether cells a and b (a != b) share a V-surface, else a V-curve, else a V-point.
/// @throws trivox::Error when a or b is not a cell index of topo
Contact contact(const Topology& topo, int a, int b);

}  // namespace trivox::vmodel
