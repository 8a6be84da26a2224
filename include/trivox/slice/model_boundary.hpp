/// @file trivox/slice/model_boundary.hpp
/// @brief The boundary faces of every cell of a model, with the faces glued between two cells
/// (the interior faces of a union, the shared faces of a multi-cell primitive) flagged, so that
/// the model's outer boundary is the faces left unglued.
///
/// A face of cell P is glued when the point just outside it lies in another cell: at 3 x 3
/// points of each of its untrimmed patches (the middles of the patch's thirds), offset along the
/// piece's outward normal by `offset` x the model's diagonal, slice::Locator::locate (which
/// honours the Booleans' trimming) finds a cell there. Two pieces sharing a surface region see it from both sides
/// with opposite outward normals, so each of the two faces finds the other's cell. A face whose
/// patches disagree (some find a cell, some none) is partly glued: BoundaryFace::glued_to is set
/// and BoundaryFace::glued is not, and it counts in `partly_glued`; such a face is not split
/// where the other cell ends (boundary_faces cuts a piece's faces only by its own conditions).
///
/// Cost: boundary_faces for every cell, one Locator over the model, nine point locations per
/// patch.
#pragma once
#include <vector>

#include "trivox/slice/boundary_faces.hpp"
#include "trivox/vmodel/vmodel.hpp"

namespace trivox::slice {

struct ModelBoundaryOptions {
  BoundaryFaceOptions faces;
  /// The distance of the test point from the face, relative to the model's diagonal; the
  /// locator's tolerance is a thousandth of it.
  double offset = 1e-6;
};

struct ModelBoundary {
  /// Every cell's boundary faces (boundary_faces), in cell order, with glued and glued_to set.
  std::vector<BoundaryFace> faces;
  double outer_area = 0.0;  ///< the faces with glued_to == -1: the model's outer boundary
  double glued_area = 0.0;  ///< the faces with glued (each shared region counts once per side)
  int partly_glued = 0;     ///< faces with glued_to >= 0 but not glued
};

/// The boundary faces of every cell of `model` with their gluing.
/// @throws trivox::Error as boundary_faces (naming the cell), and (bad_input) for a model
///         without cells or an offset not in (0, 1e-2]
ModelBoundary model_boundary(const vmodel::VModel& model, const ModelBoundaryOptions& options = {});

}  // namespace trivox::slice
