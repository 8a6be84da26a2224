/// @file trivox/fillet/fillet.hpp
/// @brief The volumetric fillet between two cells: from the intersection of two boundary faces
/// to the fillet trivariates and their quality report.
///
/// Masalha, Cirillo & Elber 2021 for two primary surfaces S_1, S_2 (faces of two
/// cells, in R^k with their properties): per component C of S_1 n S_2 (geom/surface_intersection)
/// the rails at distances d_1, d_2 (Sec. 1.2, fillet/rails.hpp), the sub-regions S^_i between C
/// and the rails (Sec. 1.5 and 4.3, fillet/compose.hpp), the blending surface S_b (Alg. 1, or
/// the flend section, fillet/blend_surface.hpp) and the ruled-volume fillet with parametrically
/// blended properties (Alg. 2, Sec. 7.1, fillet/ruled_fillet.hpp). S_b interpolates the
/// sub-regions' boundary curves on the rails, so the fillet's faces meet each other exactly.
///
/// Construction (FilletOptions::construction): `ruled`, the ruled volume of Alg. 2 in two cells
/// (fillet/ruled_fillet.hpp), `vbs`, the volumetric Boolean sum of Sec. 3.2 / Alg. 3 with
/// Appendix A's division, three cells without collapsed faces (fillet/vbs_fillet.hpp), or
/// `vrep`, the half volumetric Boolean sum of Sec. 5 / Alg. 6, one trimmed cell
/// (fillet/vrep_fillet.hpp). All take the same S^_1, S^_2, S_b and fill the same region.
///
/// Quality (per fillet, either construction): the positional gap between the cells' faces on
/// S_i and S_i, and on S_b and S_b (closest points), the largest angle between the tangent planes
/// of the cells' faces on S_b and of S_i along the rails (G1), the range of det J at interior
/// sample points of every cell (its sign: sampled, not bounded), the C0 glue (largest distance
/// between the cells' shared faces at samples), and the largest jump of the properties between
/// the cells' faces on S_i and S_i at the same point.
/// Cost: one surface intersection, two rails, two compositions or fits, one blend, one ruled or
/// VBS construction; the report samples a few thousand points on faces and, for det J, 36 or 24
/// points per knot span along C and cell.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "trivox/fillet/blend_surface.hpp"
#include "trivox/fillet/compose.hpp"
#include "trivox/fillet/rails.hpp"
#include "trivox/fillet/vbs_fillet.hpp"
#include "trivox/fillet/vrep_fillet.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/tensor_spline.hpp"

namespace trivox::fillet {

/// How the fillet volume is built from S^_1, S^_2 and S_b.
enum class Construction {
  ruled,  ///< Alg. 2: T = (1 - w) S^_12 + w S_b, two cells (the halves on S^_1 and S^_2)
  vbs,    ///< Sec. 3.2, Alg. 3, Appendix A: three volumetric Boolean sums T_1 (at C), T_2, T_3 (at the rails)
  vrep,   ///< Sec. 5, Alg. 6: the half volumetric Boolean sum T_hbs trimmed by S^_1, S^_2, S_b (+ caps): one V-cell
};
/// "ruled", "vbs", "vrep".
const char* construction_name(Construction c) noexcept;
/// Parses a construction_name; false (out unchanged) for anything else.
bool construction_from_name(const char* name, Construction& out) noexcept;

struct FilletOptions {
  std::array<double, 2> distance{1.0, 1.0};  ///< d_1 on S_1, d_2 on S_2 (model units), > 0
  BlendOptions blend;                        ///< section, tau, dip, angle tolerance
  /// Sub-regions: compose, fit, matched (Alg. 4-5) or automatic (compose, else matched, else fit)
  SubregionMethod method = SubregionMethod::automatic;
  std::array<bool, 2> flip{false, false};    ///< rail i on the other side of C
  /// Absolute tolerance (model units) of intersection points, rails and fits; <= 0: 1e-7 of the
  /// diagonal of the two cells' bounding box.
  double tolerance = 0.0;
  Construction construction = Construction::ruled;
  VbsOptions vbs;  ///< Appendix A's ratio rho and the join tolerance, for Construction::vbs
  VrepOptions vrep;  ///< the join tolerance, for Construction::vrep
};

/// Orders and control-point counts, as Masalha et al. 2021, Table 1 lists them.
struct SplineShape {
  std::vector<int> orders, counts;
};

struct FilletQuality {
  Construction construction = Construction::ruled;
  std::array<double, 2> gap{0.0, 0.0};        ///< max distance from the cells' faces on S^_i to S_i
  double blend_gap = 0.0;                     ///< max distance from the cells' faces on S_b to S_b
  std::array<double, 2> g1_angle{0.0, 0.0};   ///< max angle (rad) of the cells' S_b faces to S_i's tangent plane on rail i
  double det_min = 0.0, det_max = 0.0;        ///< det J over interior sample points of all cells
  std::vector<std::array<double, 2>> cell_jacobian;  ///< per cell (Fillet::cells order): sampled det J min, max
  /// per cell: |int det J|, exact to rounding (by the divergence theorem, over the six faces);
  /// vrep: the trimmed cell's, |T_hbs| - |W_1| - |W_2| (VrepReport has the parts)
  std::vector<double> cell_volume;
  /// C0 glue: max xyz distance between the cells' shared faces at samples (ruled: the halves'
  /// faces from C to S_b(u, 1/2); vbs: D_1, D_2, D_b). 0 when they share control points.
  double glue = 0.0;
  std::array<double, 2> property_jump{0.0, 0.0};  ///< max |g_fillet - g_i| on S^_i (0 without properties)
  std::array<bool, 2> composed{false, false}; ///< S^_i by exact composition (else fitted)
  std::array<double, 2> rail_error{0.0, 0.0}; ///< rails: largest deviation from the exact offset
  SplineShape face[2], sub[2], blend, fillet; ///< S_1, S_2, S^_1, S^_2, S_b, the first cell
  std::vector<SplineShape> cells;             ///< every cell, in Fillet::cells order
  VbsReport vbs;                              ///< Construction::vbs: Appendix A's division
  VrepReport vrep;                            ///< Construction::vrep: the trimming solid, caps, containment
  double seconds = 0.0;                       ///< time to build this fillet
  /// "positive", "negative" (never after orientation) or "changes sign".
  std::string jacobian() const;
};

struct Fillet {
  /// The fillet's cells, in R^k: ruled {a on S^_1, b on S^_2} (ruled_fillet.hpp); vbs
  /// {T_1 at C, T_2 at rail 1, T_3 at rail 2} (vbs_fillet.hpp); vrep {T_hbs}, trimmed
  /// (vrep_fillet.hpp).
  std::vector<spline::Trivariate> cells;
  /// vrep only: cells[0]'s trimming (Alg. 6): the solid {W_1, W_2} beyond S_b and the caps'
  /// trimming curves (VrepFillet); empty for the other constructions.
  std::vector<spline::Trivariate> beyond;
  std::vector<vmodel::FaceTrim> caps;
  FilletQuality quality;
  /// The rails of the intersection component this fillet belongs to (over the whole component,
  /// also for a matched piece of it), and the component's index in intersect_surfaces' order:
  /// what the multi-face fillet of fillet/corners.hpp (Masalha et al. 2021,
  /// Sec. 6) joins at the corners.
  RailPair rails;
  std::size_t component = 0;

  /// Cell c as a V-model cell called `name`: plain, or for vrep the trimmed V-cell
  /// (VrepFillet::cell: T_hbs without {W_1, W_2}).
  vmodel::VCell vcell(std::size_t c, const std::string& name) const;
};

/// The outward sign of a cell's face: +1 when the face's S_u x S_v points out of the cell.
double outward_sign(const spline::Trivariate& cell, spline::Face face);

/// The fillets between face f1 of cell1 and face f2 of cell2, one per intersection component, or
/// with matched Bezier pairs (SubregionMethod::matched, or automatic on B-spline faces where
/// Lemma 1 holds; fillet/matched.hpp, Masalha et al. 2021, Alg. 4-5) one
/// per piece, in order along C.
/// @throws Error (bad_input) for cells of different dimensions, faces that do not intersect
///         ("... do not intersect"), an intersection that is only a point, distances or
///         parameters out of range or rails leaving their face (the message names the face);
///         Error (failed) when a step cannot be completed
std::vector<Fillet> fillet_faces(const spline::Trivariate& cell1, spline::Face f1, const spline::Trivariate& cell2,
                                 spline::Face f2, const FilletOptions& options);

}  // namespace trivox::fillet
