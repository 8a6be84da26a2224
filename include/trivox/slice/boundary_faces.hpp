/// @file trivox/slice/boundary_faces.hpp
/// @brief The trimmed boundary faces of a Boolean's piece (a trimmed cell, vmodel/boolean.hpp)
/// and their areas.
///
/// A trimmed cell is the part of its trivariate's image inside every `within` cell and outside
/// every cell of its `without` lists (Massarwi & Elber 2016, Sec. 4). Its boundary is made of
/// (a) parts of its own trivariate's six faces, where the conditions admit them, and (b) parts of
/// the condition cells' faces (the wall of a hole: a subtracted cylinder's face inside a box),
/// where the point lies inside the cell's trivariate and satisfies every other condition.
/// Each such face is cut by its intersection curves (geom::intersect_surfaces, recomputed here:
/// the stored VCell::trim_curves do not say which face cut them) with the faces of the other
/// trivariates (the cell's own and its direct conditions'), and the cut face is split and
/// classified by geom::trim_face, membership decided by slice::Locator (exact up to its
/// tolerance). Only direct conditions are used as cutters: a condition cell that is itself
/// trimmed is tested exactly, but its own conditions' faces do not cut.
///
/// Every boundary face is reported, also faces glued to another piece of the same model (the
/// interior faces of a union); slice::model_boundary (model_boundary.hpp) flags those. Coplanar
/// (coincident) faces are not cut (intersect_surfaces reports no curve there) and are classified
/// as a whole.
///
/// Contacts (geom::IntersectionContact): where a face of one solid (the cell's trivariate, a
/// `within` cell, or the cells of one `without` list) touches a face of another tangentially
/// along a curve, or coincides with it over a region (curved faces too), boundary_faces throws
/// naming both faces and the place: such faces are not cut there, so the piece would be
/// non-manifold or wrong. Isolated point contacts bound nothing and are ignored; faces of one
/// solid (the cells of a primitive) meet so by construction and are not checked. Cutting curves
/// within the trimming tolerance of a point, or along a side of the face's parameter rectangle
/// (where the cells of a primitive meet along edges; geom::trim_face sets those aside), are left
/// out before trimming.
///
/// Each face carries its orientation: whether the piece's outward normal is S_u x S_v of the
/// face's surface or its opposite (face_orientation below, times the sign of the source
/// trivariate's Jacobian determinant, reversed for a `without` cell's face: the piece lies
/// outside that cell), and its untrimmed patches (geom::untrim), from which its area and the
/// piece's measures (piece_measures.hpp) are integrated.
///
/// Cost: 6 x 6 x (1 + C)^2 surface intersections for C direct conditions, then per face the cost
/// of geom::trim_face, one point location per condition and region, and the untrimming.
#pragma once
#include <string>
#include <vector>

#include "trivox/geom/trimmed_surface.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/vmodel/vmodel.hpp"

namespace trivox::slice {

/// One trimmed face of a piece's boundary.
struct BoundaryFace {
  int cell = -1;        ///< the model's cell
  /// -1: the cell's own trivariate; k >= 0: its k-th direct condition cell (the `within` cells in
  /// order, then the cells of the `without` lists in order)
  int source = -1;
  std::string source_name;  ///< that trivariate's cell name
  spline::Face face = spline::Face::u0;  ///< which face of that trivariate
  geom::TrimmedSurface surface;  ///< one kept region (adjacent kept regions are not merged)
  double area = 0.0;
  /// +1 when the piece's outward normal points along S_u x S_v of `surface`, -1 when against:
  /// face_orientation(face) x the sign of the source trivariate's Jacobian determinant
  /// (geom::signed_volume), x -1 for the face of a `without` cell.
  int orientation = 1;
  /// geom::untrim(surface): Bezier patches tiling the region, with S's orientation.
  geom::Untrimmed patches;
  /// Set by slice::model_boundary only (false and -1 here): `glued` when the point just outside
  /// the face (along the outward normal, at 3 x 3 points of every patch) lies in another cell of
  /// the model, so the face is interior to the model; `glued_to` the cell found there at the
  /// first patch that found one (-1: none). A face with glued_to >= 0 and !glued is partly glued.
  bool glued = false;
  int glued_to = -1;
};

/// The side of a right-handed trivariate's face that S_u x S_v of spline::boundary_face points
/// to: +1 outward (u1, v0, w1), -1 inward (u0, v1, w0). With X_u, X_v, X_w the trivariate's
/// partials and det J = X_u . (X_v x X_w) > 0: the u faces have S_u x S_v = X_v x X_w (along
/// +X_u), the v faces X_u x X_w (along -X_v), the w faces X_u x X_v (along +X_w).
int face_orientation(spline::Face face) noexcept;

struct BoundaryFaceOptions {
  /// Relative tolerance of geom::trim_face (ends on the boundary, chains).
  double tolerance = 1e-7;
  /// Absolute tolerance of the surface intersections (model units).
  double intersection_tolerance = 1e-10;
};

/// The trimmed boundary faces of `model.cells[cell]`, in order: its own faces u0..w1, then each
/// condition cell's faces u0..w1; the regions of one face in geom::face_regions order.
/// @throws trivox::Error (bad_input) for a cell index out of range; (failed) for faces of two
///         solids touching along a curve or coinciding over a region; and as geom::trim_face
std::vector<BoundaryFace> boundary_faces(const vmodel::VModel& model, int cell,
                                         const BoundaryFaceOptions& options = {});

/// The sum of the faces' areas.
double boundary_area(const std::vector<BoundaryFace>& faces);

}  // namespace trivox::slice
