/// @file trivox/fillet/fillet.hpp
/// @brief The volumetric fillet between two cells: from the intersection of two boundary faces
/// to the fillet trivariates and their quality report.
///
/// Masalha, Cirillo & Elber 2021 (seed 000) for two primary surfaces S_1, S_2 (faces of two
/// cells, in R^k with their properties): per component C of S_1 n S_2 (geom/surface_intersection)
/// the rails at distances d_1, d_2 (Sec. 1.2, fillet/rails.hpp), the sub-regions S^_i between C
/// and the rails (Sec. 1.5 and 4.3, fillet/compose.hpp), the blending surface S_b (Alg. 1, or
/// the flend section, fillet/blend_surface.hpp) and the ruled-volume fillet with parametrically
/// blended properties (Alg. 2, Sec. 7.1, fillet/ruled_fillet.hpp). S_b interpolates the
/// sub-regions' boundary curves on the rails, so the fillet's faces meet each other exactly.
///
/// Quality (per fillet): the positional gap between the fillet's faces on S_i and S_i (closest
/// points), the largest angle between the tangent planes of S_b and of S_i along the rails (G1),
/// the range of det J at interior points (its sign), and the largest jump of the properties
/// between the fillet's face on S_i and S_i at the same point.
/// Cost: one surface intersection, two rails, two compositions or fits, one blend; the report
/// samples a few thousand points.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "trivox/fillet/blend_surface.hpp"
#include "trivox/fillet/compose.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/tensor_spline.hpp"

namespace trivox::fillet {

struct FilletOptions {
  std::array<double, 2> distance{1.0, 1.0};  ///< d_1 on S_1, d_2 on S_2 (model units), > 0
  BlendOptions blend;                        ///< section, tau, dip, angle tolerance
  SubregionMethod method = SubregionMethod::automatic;
  std::array<bool, 2> flip{false, false};    ///< rail i on the other side of C
  /// Absolute tolerance (model units) of intersection points, rails and fits; <= 0: 1e-7 of the
  /// diagonal of the two cells' bounding box.
  double tolerance = 0.0;
};

/// Orders and control-point counts, as seed 000 Table 1 lists them.
struct SplineShape {
  std::vector<int> orders, counts;
};

struct FilletQuality {
  std::array<double, 2> gap{0.0, 0.0};        ///< max distance fillet face on S_i to S_i
  std::array<double, 2> g1_angle{0.0, 0.0};   ///< max angle (rad) of S_b to S_i's tangent plane on rail i
  double det_min = 0.0, det_max = 0.0;        ///< det J over interior sample points of both halves
  std::array<double, 2> property_jump{0.0, 0.0};  ///< max |g_fillet - g_i| on S^_i (0 without properties)
  std::array<bool, 2> composed{false, false}; ///< S^_i by exact composition (else fitted)
  std::array<double, 2> rail_error{0.0, 0.0}; ///< rails: largest deviation from the exact offset
  SplineShape face[2], sub[2], blend, fillet; ///< S_1, S_2, S^_1, S^_2, S_b, one half of T
  double seconds = 0.0;                       ///< time to build this fillet
  /// "positive", "negative" (never after orientation) or "changes sign".
  std::string jacobian() const;
};

struct Fillet {
  std::array<spline::Trivariate, 2> halves;  ///< the fillet (ruled_fillet.hpp), in R^k
  FilletQuality quality;
};

/// The outward sign of a cell's face: +1 when the face's S_u x S_v points out of the cell.
double outward_sign(const spline::Trivariate& cell, spline::Face face);

/// The fillets between face f1 of cell1 and face f2 of cell2, one per intersection component.
/// @throws Error (bad_input) for cells of different dimensions, faces that do not intersect
///         ("... do not intersect"), an intersection that is only a point, distances or
///         parameters out of range or rails leaving their face (the message names the face);
///         Error (failed) when a step cannot be completed
std::vector<Fillet> fillet_faces(const spline::Trivariate& cell1, spline::Face f1, const spline::Trivariate& cell2,
                                 spline::Face f2, const FilletOptions& options);

}  // namespace trivox::fillet
