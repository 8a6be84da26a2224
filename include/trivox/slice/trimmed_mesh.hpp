/// @file trivox/slice/trimmed_mesh.hpp
/// @brief The boundary of a model with trimmed cells (the pieces of Booleans) as a closed,
/// manifold, outward-oriented triangle mesh, tessellated from the untrimmed patches of the
/// pieces' trimmed boundary faces.
///
/// What is tessellated. slice::model_boundary gives every cell's trimmed boundary faces, each
/// untrimmed into Bezier patches (geom::untrim: Massarwi & Elber 2016, Sec. 5.1, the quads of a
/// trimmed domain with freeform sides composed with the surface), with the piece's outward
/// orientation and the faces glued between two cells flagged. The model's boundary is the faces
/// glued to nothing; with TrimmedMeshOptions::mesh.per_cell every cell's faces, glued or not, one
/// closed shell per piece, no vertex shared between pieces. A face glued in part only (covered by
/// another cell over part of its area: model_boundary does not split it there) cannot be meshed
/// correctly and is refused.
///
/// Sampling. Each patch X(s, t) on [0, 1]^2 is sampled on a uniform grid of n_s x n_t >= 2 x 2
/// segments, refined until the midpoint check of vmodel::mesh_boundary holds: at the midpoint of
/// every grid segment and the centre of every quad, the surface's distance from the chord (on the
/// patch's sides: from the segment's line, since the side is shared with a neighbour; inside:
/// along the normal, from the segment's or the triangulating diagonal's midpoint) is at most the
/// chordal tolerance; a direction where it is not gets sqrt(deviation / tol) x 1.1 times more
/// segments, at most 8 rounds. As there, the largest deviation measured is reported, not a bound.
///
/// Watertightness. Patches of different faces meet along trimming curves that each face
/// parametrises its own way (the two parameter-space images of one intersection curve), and
/// patches of one face meet along the slab lines of the untrimming, whose sides need not end
/// at the same points (T-junctions); so grids do not match by construction. Instead every
/// sample on a patch's side is projected (Gauss-Newton on the side curve in space) onto the other
/// patches' sides near it and inserted into each side it lies on, unless a sample of that side
/// already is one with it; the grid cells along a side are fanned from the cell's corner off
/// the side, and side samples that are one are welded into one vertex (single linkage over a
/// hash grid). Two samples are one when
/// - of two faces: within the weld distance in space (TrimmedMeshOptions::weld);
/// - of one face: within 3/4 of its trimmed surface's tolerance in the face's parameters (its
///   loops' gaps are at most half of it, geom::face_trim, and untrim merges events closer than
///   it, so no slab is narrower; in space the narrowest slabs are far below the weld distance).
/// And only where the sides share a curve: within a face, slab lines (sides 1 and 3, vertical in
/// the face's parameters) with slab lines and curves with curves, other contacts being corners;
/// another face's samples go only into sides on the face's loops (not every sample of which lies
/// on another side of the face), and only the samples of such sides: a loop tangent to a slab line
/// (where untrim cuts slabs at the vertical tangents of a hole) passes within the weld distance of
/// the line's samples without meeting them. Triangles that welding makes degenerate (a side of no
/// length, where a triangle-like quad or a pole collapses) are dropped; patches narrower than
/// 1e-4 of the weld distance and sides shorter than that are nothing.
///
/// A trimmed cell whose conditions admit its whole trivariate (`trivox build` restricts a piece
/// that is a parameter box to it and keeps the conditions, whose faces then lie on its own:
/// boundary_faces does not cut coplanar faces) is meshed as a plain cell: slice::trimmed_volume
/// (8^3 sub-boxes) within 1e-9 of its quadrature volume.
///
/// Orientation. The patches keep their face's orientation of S_u x S_v (geom::untrim), and each
/// face carries the piece's outward side (BoundaryFace::orientation); the triangles follow it,
/// so they are counter-clockwise seen from outside and the enclosed volume is positive.
///
/// Properties. A vertex takes the property coordinates of the patch that made it first (faces
/// in model_boundary's order: cell by cell, own faces first). Where those are not the piece's
/// (a face of a condition cell, the wall of a hole carrying the subtracted cell's values) or the
/// piece blends its inputs (an intersection cell), the point just inside the piece (1e-6 of the
/// diagonal against the vertex normal) is located (slice::Locator) and the piece's blended
/// properties there are taken, as `trivox locate` reports them; where that point is in no cell
/// the patch's values stay.
///
/// cell_volume is the sum of the pieces' exact volumes from the same faces (slice::piece_measures
/// on them), which also checks that each piece's boundary closes (refused otherwise).
///
/// Cost: a trimmed_volume per trimmed cell, model_boundary (surface intersections, trimming and untrimming of every cell), then per
/// patch (n_s + 1)(n_t + 1) evaluations per round plus the midpoints, one hash-grid query and a
/// few Gauss-Newton steps per side sample near other sides, and one point location per vertex
/// that needs the piece's properties. Deterministic (no threads; fixed orders).
#pragma once
#include "trivox/slice/model_boundary.hpp"
#include "trivox/vmodel/boundary_mesh.hpp"
#include "trivox/vmodel/vmodel.hpp"

namespace trivox::slice {

struct TrimmedMeshOptions {
  /// Chordal tolerance (absolute, or relative to slice::model_diagonal), per_cell, and the caps
  /// on segments per patch direction and on triangles, as for vmodel::mesh_boundary.
  vmodel::MeshOptions mesh;
  /// The faces, their gluing and untrimming.
  ModelBoundaryOptions boundary;
  /// The weld distance between faces relative to the model's diagonal, in (0, 1e-3] (at most
  /// half the chordal tolerance is used): side samples of two faces this close are one vertex,
  /// and a sample this close to another face's patch side is inserted into it. It must exceed
  /// the gaps between two faces' images of one trimming curve (about 1e-12 of the diagonal for
  /// planar and cylindrical cuts, 1e-7 for bicubic ones) and stay below the width of the
  /// narrowest patches; patches of one face meet to rounding and use 1e-4 of it.
  double weld = 1e-7;
};

/// True when some cell of `model` is trimmed (not VCell::plain()): its boundary is not its
/// trivariate's faces, and mesh_trimmed_boundary is needed instead of vmodel::mesh_boundary.
bool has_trimmed_cells(const vmodel::VModel& model) noexcept;

/// Tessellates the boundary of `model` from its trimmed boundary faces (see the file comment).
/// Plain cells are meshed the same way (their six faces untrimmed into their Bezier pieces).
/// @throws trivox::Error (bad_input) for options out of range and when the tolerance needs more
///         than max_segments or max_triangles; (failed) for a face glued in part only, a piece
///         whose boundary does not close (piece_measures' checks), an empty boundary; and as
///         model_boundary (naming the cell)
vmodel::BoundaryMesh mesh_trimmed_boundary(const vmodel::VModel& model, const TrimmedMeshOptions& options = {});

/// Tessellates the given faces (any subset of model_boundary's, oriented as there) into one
/// welded mesh of `tolerance` (absolute), with weld distance `weld_distance`; the properties are
/// the patches' own coordinates. cell_volume is left 0. The building block of
/// mesh_trimmed_boundary, for tests and callers with their own faces.
/// @param property_names  names of the coordinates 3.. of the faces' surfaces
/// @throws trivox::Error (bad_input) when the tolerance needs more than max_segments or
///         max_triangles (options.max_segments, options.max_triangles)
vmodel::BoundaryMesh mesh_faces(const std::vector<BoundaryFace>& faces, double tolerance, double weld_distance,
                                const std::vector<std::string>& property_names,
                                const vmodel::MeshOptions& options = {});

}  // namespace trivox::slice
