/// @file trivox/vmodel/boundary_mesh.hpp
/// @brief The boundary of a V-model as a closed triangle mesh with per-vertex properties, and
/// the statistics that check such a mesh (volume, area, edge-manifoldness, shells, Euler
/// characteristic).
///
/// What is tessellated. With the topology of the model (topology.hpp, Massarwi & Elber 2016,
/// Sec. 3.1), every boundary V-surface, i.e. a half-V-surface glued to nothing, becomes a
/// structured grid of triangles; interior V-surfaces (two cells' coinciding faces) are left out,
/// so a complex of cells glued face to face gives one closed surface. Two faces of the same cell
/// that coincide (a cell closed onto itself, such as a full ring of the torus primitive, whose
/// w0 and w1 faces meet) are interior as well and left out. The topology is built with the
/// matching distance 1% of the chordal tolerance (at least its default, 1e-9 of the diagonal):
/// geometry that close is one at the mesh's resolution, and rings closed by fitting (fillets)
/// meet themselves only to about 1e-5 of their size. With MeshOptions::per_cell every
/// cell's own boundary is tessellated instead, glued or not: one closed shell per cell, sharing
/// no vertex with another cell's.
///
/// Sampling. Each face is sampled on a grid uniform in its two parameters, n_s x n_t segments.
/// The counts come from the chordal tolerance `tol` in two steps. (1) An estimate from the
/// second derivatives: the components of S_ss, S_st, S_tt along the unit normal (samples where
/// the normal vanishes are skipped) are sampled (three points per knot span, at most 64 points
/// per direction) to M_ss, M_st, M_tt, and n_s, n_t are chosen so that each term of the
/// interpolation error bound (h_s^2 M_ss + 2 h_s h_t M_st + h_t^2 M_tt) / 8 is at most tol / 3
/// (h = parametric length / n). (2) A check by refinement: the surface is evaluated at the
/// midpoint of every grid segment and the centre of every quad. On the face's boundary the
/// distance from the segment's line counts (the edge is shared with the neighbouring face and
/// must follow the curve); inside, the distance along the quad's normal from the midpoint of
/// the segment, or of the quad's triangulating diagonal (a planar face deviates by nothing
/// however it is parametrised). A face direction where this exceeds tol gets
/// sqrt(deviation / tol) * 1.1 times more segments, and the check repeats, at most 8 rounds.
/// The result reports the largest deviation measured (`max_deviation`). This is a measurement
/// at midpoints, not a rigorous bound: a feature between two samples narrower than a grid step
/// (a crease in the middle of a knot span) can deviate more.
///
/// Watertightness. Faces that share an edge (a V-curve) use the same samples on it: the counts
/// are unified over classes of edges (union-find: the two opposite edges of a face are one class,
/// being the two ends of one grid direction, and a V-curve joins the faces that use it), each
/// class taking the largest count any member needs. The vertices on a V-curve and at a V-point
/// are evaluated once, from the first face that needs them, and their indices reused by every
/// other face (properties too: where cells meeting at an edge carry different properties, the
/// first cell's values are kept). A collapsed edge (no V-curve: a pole or an axis) maps all its
/// samples to one vertex, and the triangles this makes degenerate (two equal indices) are
/// dropped, so the mesh stays manifold. Degenerate faces (no area) have no half-V-surface and
/// are skipped. Cells glued along faces that do not coincide as a whole (one face meeting half of
/// another) are not glued by the topology; both faces are then boundary, the mesh has an inner
/// wall, and edge_manifold() reports it.
///
/// Orientation. The natural normal of a face, S_s x S_t ((s, t) the two other directions in
/// increasing order), points out of a right-handed cell (det J > 0) on u1, w1, v0 and into it on
/// u0, w0, v1; each face is oriented by that rule and the sign of the cell's quadrature volume,
/// so every normal points out of the solid and enclosed_volume() is positive.
///
/// Refused input: a cell trimmed by a Boolean (`within`, `without` or trimming curves): its
/// boundary is not its trivariate's faces, and meshing it needs the trimmed faces untrimmed
/// first, which trivox does not do yet. The error names the cell.
///
/// Cost: O(faces * n_s * n_t * prod(order) * dim) evaluations per round (typically 1-2 rounds),
/// plus the topology (topology.hpp). Memory: O(vertices * dim + triangles). Deterministic: the
/// same model and options give the same mesh, vertex and triangle order included.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "trivox/vmodel/vmodel.hpp"

namespace trivox::vmodel {

struct MeshOptions {
  /// Absolute chordal tolerance in model units; 0 means relative_tolerance times the diagonal
  /// of the model's xyz control box. >= 0, finite.
  double tolerance = 0.0;
  /// Used when tolerance == 0. In (0, 0.1].
  double relative_tolerance = 1e-3;
  /// Every cell's own boundary as its own shell, instead of the model's boundary.
  bool per_cell = false;
  /// Most segments along one direction of one face (the tolerance asks for more: refused).
  int max_segments = 2048;
  /// Most triangles of the whole mesh (refused above, before the grids are built).
  std::int64_t max_triangles = 20'000'000;
};

struct BoundaryMesh {
  std::vector<std::array<double, 3>> vertices;
  /// The model's property names (coordinates 3.. of its control points).
  std::vector<std::string> property_names;
  /// vertices.size() x property_names.size() values, vertex after vertex.
  std::vector<double> properties;
  /// Vertex indices, counter-clockwise seen from outside the solid.
  std::vector<std::array<int, 3>> triangles;

  double tolerance = 0.0;      ///< the absolute chordal tolerance used
  double max_deviation = 0.0;  ///< largest distance surface - chord measured at the midpoints
  int faces = 0;               ///< faces (half-V-surfaces) tessellated
  int dropped_triangles = 0;   ///< degenerate triangles of collapsed edges left out
  int rounds = 0;              ///< sampling rounds of the midpoint check
  /// The sum of the cells' volumes by quadrature (geom::volume), for comparison with
  /// enclosed_volume(): the tessellation error is the difference.
  double cell_volume = 0.0;
};

/// Tessellates the boundary of `model` (see the file comment).
/// @param model    cells with at least 3 coordinates; free surfaces (NamedSurface) are ignored
/// @param options  tolerance and mode
/// @throws trivox::Error (bad_input) naming the cell for a trimmed cell ("cell "name" (3): trimmed
///         by a Boolean ...; expected untrimmed cells"), for options out of range, and when the
///         tolerance needs more than max_segments or max_triangles
BoundaryMesh mesh_boundary(const VModel& model, const MeshOptions& options = {});

/// The indices of the properties named r, g, b in `names` (sRGB components in 0..1, the model
/// format's colour), or nothing when any is missing.
std::optional<std::array<int, 3>> colour_properties(const std::vector<std::string>& names);

/// The colour of vertex v as 8-bit sRGB: each component clamped to [0, 1] and rounded from
/// c * 255; `rgb` from colour_properties.
std::array<std::uint8_t, 3> vertex_colour(const BoundaryMesh& mesh, std::size_t v, const std::array<int, 3>& rgb);

/// The signed volume enclosed: the divergence theorem, sum over triangles of
/// det[a - o, b - o, c - o] / 6 with o the centre of the vertices' box (fewer cancellations).
/// Positive when the triangles are counter-clockwise seen from outside.
double enclosed_volume(const BoundaryMesh& mesh);

/// The sum of the triangles' areas.
double surface_area(const BoundaryMesh& mesh);

/// The edge checks of a closed orientable surface.
struct EdgeReport {
  std::int64_t edges = 0;            ///< distinct undirected edges
  std::int64_t boundary_edges = 0;   ///< used by one triangle
  std::int64_t non_manifold_edges = 0;  ///< used by more than two, or twice in one direction
  std::int64_t degenerate_triangles = 0;  ///< with a repeated vertex index
  /// Every edge used by exactly two triangles, in opposite directions, and no degenerate triangle.
  bool manifold() const noexcept {
    return boundary_edges == 0 && non_manifold_edges == 0 && degenerate_triangles == 0;
  }
};
EdgeReport edge_report(const BoundaryMesh& mesh);

/// Whether every edge is shared by exactly two triangles with opposite directions.
bool edge_manifold(const BoundaryMesh& mesh);

/// The connected components of triangles, two triangles being connected when they share an edge.
int shell_count(const BoundaryMesh& mesh);

/// V - E + F over the vertices used by triangles, the distinct edges and the triangles (2 per
/// shell for closed surfaces of genus 0: a sphere-like solid; 0 for a torus).
std::int64_t euler_characteristic(const BoundaryMesh& mesh);

}  // namespace trivox::vmodel
