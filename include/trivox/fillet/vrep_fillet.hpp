/// @file trivox/fillet/vrep_fillet.hpp
/// @brief The V-rep fillet: one tensor-product trivariate containing the fillet space, the half
/// volumetric Boolean sum of S^_1 and S^_2, trimmed by the fillet's boundary surfaces S^_1, S^_2,
/// S_b (and, for an open C, the two capping surfaces).
///
/// Masalha, Cirillo & Elber 2021, Sec. 5, Def. 5.1, Lemma 2 and Alg. 6, in the V-rep
/// framework of Massarwi & Elber 2016 (Def. 3.2: a V-cell is the part of a trivariate
/// delineated by trimming surfaces).
///
/// - T_hbs(u, v, w) = S^_1(u, v) + S^_2(u, w) - C(u) (Def. 5.1, Alg. 6 line 2), with v measured
///   on S^_1 from C (v = 0) to rail 1 (v = 1) and w on S^_2 from C (w = 0) to rail 2 (w = 1). By
///   Lemma 2 its face w0 is S^_1 and its face v0 is S^_2; its edges (v, w) = (1, 0) and (0, 1)
///   are the rails, (1, 1) is the far corner K = R_1 + R_2 - C. In a planar corner each section is
///   the parallelogram on the two legs; S_b runs from rail to rail inside it.
/// - The trimming surfaces L = {S^_1, S^_2, S_b} (+ caps, Alg. 6 lines 3-12): S^_1 and S^_2 are
///   T_hbs's own faces and so are the caps S_c^i = T_hbs(0, v, w), T_hbs(1, v, w) (lines 5-6), so
///   only S_b cuts the trivariate. trivox's V-cells are trimmed by solids, not by surfaces
///   (vmodel::VCell::without: point membership exact by inversion, as the Booleans use it, and
///   what slice::apply_trimming and Locator::admits honour), so S_b is given as the face of the
///   solid W beyond it: W_1 = Rld(S_b[0, v_b], T_hbs v1) and W_2 = Rld(S_b[v_b, 1], T_hbs w1
///   reversed), the ruled volumes (Massarwi & Elber 2016, Sec. 3.2.2) between S_b
/// and the far faces of T_hbs,
///   glued along Rld(C_b, K). The fillet is the cell {T_hbs without {W_1, W_2}}: its boundary is
///   S^_1, S^_2 (T_hbs), S_b (W's face w0) and, for an open C, the caps: T_hbs's end faces
///   trimmed by the loop of Alg. 6 line 11: C_u, C_v (the cap's edges v = 0, w = 0) and C_Sb, where
///   W's end faces meet them (vmodel::FaceTrim on T_hbs u0 and u1, C_Sb in the cap's (v, w),
///   for the record: membership does not depend on them). A closed C gives no caps (the ends are
///   one section).
/// - v_b splits S_b where it is nearest to C (Appendix A's projection, Eq. A.1, of C(1/2) on
///   S_b(1/2, v), as the VBS division), so each W_i is ruled between S_b from a rail to C_b and
///   one far face from that rail to K: curves of the same turn, no fold.
///
/// Properties (R^k, k > 3): T_hbs's are Def. 5.1's in the property coordinates, so g_1 on S^_1 and
/// g_2 on S^_2 where they agree on C. Where they differ (Eq. 8's jump) one trivariate cannot carry
/// both: C gets the mean of g_1 and g_2, and the faces w0, v0 are then set to S^_1's and S^_2's
/// control nets except that edge, so the faces deviate from g_i by up to half the jump, fading
/// within the first span from C (VrepReport::property_jump), as the VBS fillet's T_1 does. S_b's
/// own properties (g_b of Sec. 7.1) are not used: inside, the fillet carries T_hbs's.
///
/// Jacobians: T_hbs's det J is that of Def. 5.1 (the sine of the dihedral angle at C in a
/// planar corner, no degenerate edge); W_i collapses at its rail (a ruled volume between two
/// surfaces sharing an edge), positive inside when it does not fold.
///
/// Volume: W lies in T_hbs when S_b does (VrepReport::outside says by how much it does not), so
/// the trimmed cell's volume is |T_hbs| - |W_1| - |W_2|, each integral exact to rounding.
///
/// Cost: one half Boolean sum (the control nets of S^_1 and S^_2 added: n_u x n_v x n_w points),
/// two ruled volumes, a few hundred point inversions for the report and
/// the caps' trimming curves.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "trivox/spline/tensor_spline.hpp"
#include "trivox/vmodel/vmodel.hpp"

namespace trivox::fillet {

struct VrepOptions {
  /// Largest gap allowed between boundaries that must coincide (S^_1(u, 1) and S^_2(u, 0); S_b's
  /// rows on the rails and S^_i's), relative to the diagonal of S_b's control box, as
  /// VbsOptions::tolerance. They are joined exactly before the construction.
  double tolerance = 1e-6;
};

/// What the construction chose and found.
struct VrepReport {
  double v_b = 0.0;      ///< W_1 covers S_b[0, v_b], W_2 S_b[v_b, 1]
  double c_gap = 0.0;    ///< largest distance between S^_1(u, 1) and S^_2(u, 0) (control points) before the join
  std::array<double, 2> rail_gap{0.0, 0.0};  ///< the same between S_b's rails and S^_i's
  double property_jump = 0.0;  ///< largest |g_1 - g_2| over C's control points (Eq. 8's jump)
  bool closed = false;         ///< C closed: T_hbs's end faces coincide, no caps
  /// Open C: the largest distance from S_b's end sections S_b(0, s), S_b(1, s) to the caps
  /// T_hbs(0, v, w), T_hbs(1, v, w) at 65 samples each (0 when each section lies in its cap, as
  /// in a planar corner): how far the trimming curves C_Sb are from S_b's.
  double cap_gap = 0.0;
  /// Largest distance by which S_b leaves T_hbs, at 33 x 17 samples (inverted in T_hbs; 0 when
  /// inside): the part of the fillet space T_hbs misses.
  double outside = 0.0;
  double hbs_volume = 0.0;                    ///< |int det J| over T_hbs
  std::array<double, 2> beyond_volume{0, 0};  ///< the same over W_1, W_2
  /// Sampled det J of W_1, W_2 (per span along C its midpoint, times 6 x 4 across): min, max.
  std::array<std::array<double, 2>, 2> beyond_jacobian{};
  bool reversed = false;  ///< u was reversed to make det J of T_hbs positive
};

/// The V-rep fillet's parts (see the file comment).
struct VrepFillet {
  spline::Trivariate hbs;                    ///< T_hbs in R^k, on [0, 1]^3
  std::array<spline::Trivariate, 2> beyond;  ///< W_1, W_2 in R^k: the solid beyond S_b (w = 0 on S_b)
  /// Open C: the trimming curves of T_hbs's faces u0 and u1 (C_Sb in the cap's (v, w)); empty
  /// for a closed C.
  std::vector<vmodel::FaceTrim> caps;

  /// The trimmed V-cell: hbs, without = {{beyond[0] as `<name>.beyond.1`, beyond[1] as
  /// `<name>.beyond.2`}}, trim_curves = caps, properties its own (BlendRule::first).
  vmodel::VCell cell(const std::string& name) const;
};

/// @param sub1   S^_1(u, v) in R^k: v = 0 on rail 1, v = 1 on C (as ruled_fillet and vbs_fillet)
/// @param sub2   S^_2(u, v) in R^k: v = 0 on C, v = 1 on rail 2; u along C as in sub1
/// @param blend  S_b(u, v): v = 0 on rail 1, v = 1 on rail 2; in R^3 or R^k (its properties are
///               not used: the trimming solid carries T_hbs's far faces' and S_b's only for
///               membership)
/// @throws Error (bad_input) for the inputs ruled_fillet refuses or boundaries apart by more
///         than the tolerance; Error (failed) when the projection parameter v_b of C(1/2) on S_b
///         lands on a rail, or when det J of W_1 or W_2 changes sign at the samples (S_b folds against
///         T_hbs's far faces)
VrepFillet vrep_fillet(const spline::Surface& sub1, const spline::Surface& sub2, const spline::Surface& blend,
                       const VrepOptions& options = {}, VrepReport* report = nullptr);

}  // namespace trivox::fillet
