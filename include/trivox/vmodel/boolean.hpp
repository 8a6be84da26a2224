/// @file trivox/vmodel/boolean.hpp
/// @brief Union, intersection and subtraction of V-models (Massarwi & Elber 2016,
/// Sec. 4, Alg. 1-3), with exact point membership.
///
/// The result's cells are the pieces of the inputs' cells, mutually exclusive, as in the paper:
/// - intersection (Alg. 1, V-Intersect): one cell per pair (a of A, b of B): a's trivariate
///   trimmed to lie within b; it keeps both trivariates and both attribute fields, blended by
///   the chosen rule (VCell::blend);
/// - subtraction A - B (Alg. 2, V-Subtract): each a of A trimmed to lie in no cell of B (the
///   whole of B at once, the paper's "simpler and probably more robust" variant);
/// - union (Alg. 3, V-Union): the cells of A n B, A - B and B - A.
/// The trimming is kept as the other input's cells themselves (VCell::within, VCell::without),
/// not as trimming surfaces: whether a point belongs to a cell is then decided exactly by point
/// inversion in those cells (slice::Locator), which is what the slicer needs. Pairs whose
/// bounding boxes are disjoint are dropped from intersections and not listed in subtractions,
/// so the result stays small for models that touch only locally. The distance blend (Eq. 2)
/// stores each input's boundary: the faces of its cells that are glued to no other cell
/// (vmodel/topology.hpp); for an input that is itself trimmed these are its trivariates' free
/// faces, an approximation of its true boundary.
///
/// Trimming curves: each piece's faces carry the curves where the other input's cells' faces cut
/// them (VCell::trim_curves, in the face's parameters), as the boundary V-surfaces of the paper
/// carry trimming curves; membership does not depend on them.
///
/// Cost: O(|A| * |B|) box tests, and 36 surface intersections per pair of cells whose boxes
/// meet (when trim_curves); the result holds copies of the trivariates it refers to.
#pragma once
#include <string>

#include "trivox/vmodel/vmodel.hpp"

namespace trivox::vmodel {

enum class BooleanOp { union_op, intersection, subtraction };

/// "union", "intersection", "subtraction".
const char* boolean_op_name(BooleanOp op) noexcept;

struct BooleanOptions {
  /// How intersection cells blend the two inputs' properties.
  BlendRule blend = BlendRule::sum_clip;
  /// k of the distance blend (Massarwi & Elber 2016, Eq. 2 with d^k), > 0.
  double power = 1.0;
  /// Names of the result's cells: intersection cells are "<a><join><b>"; cells of A - B and
  /// B - A keep their names. Repeated names get a suffix ".2", ".3", ...
  std::string join = "&";
  /// Compute the trimming curves (VCell::trim_curves): where the other input's cell faces cut
  /// each piece's faces, by surface-surface intersection (geom/surface_intersection.hpp).
  bool trim_curves = true;
};

/// The Boolean operation `op` of models a and b (same property names in the same order, same
/// units).
/// @throws trivox::Error (bad_input) naming the difference when the properties or units differ,
///         when either model has no cells, or for a distance blend power <= 0
VModel boolean(const VModel& a, const VModel& b, BooleanOp op, const BooleanOptions& options = {});

}  // namespace trivox::vmodel
