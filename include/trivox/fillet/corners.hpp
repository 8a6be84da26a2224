/// @file trivox/fillet/corners.hpp
/// @brief Fillets over several faces whose intersection curve is only piecewise C1, and the
/// singular fillets that bridge the gaps at its convex corners.
///
/// Masalha, Cirillo & Elber 2021, Sec. 6 and 6.1, Fig. 12 (a box and a cylinder).
/// Two bodies, given as lists of faces S_{1,i} (side 1) and S_{2,j} (side 2), meet along
/// C = U C_{i,j}, C_{i,j} = S_{1,i} n S_{2,j}: closed (or open) and only piecewise C1.
///
/// Step 1 (Sec. 6): one fillet per face pair and intersection component (fillet_faces, any
/// sub-region method, the ruled construction of Alg. 2). The pieces are chained where their end
/// points o coincide (within the join tolerance). At each junction the rails' ends are compared:
/// - both sides' rails meet, or C turns by less than CornerOptions::smooth_angle: the faces join
///   G1 there (the lamp of Fig. 15): nothing to add;
/// - one side's rails meet (its body has an edge through o, perpendicular to the other body's
///   face there, so both its rails end on that edge at the same point r) and the other side's
///   leave a gap between p (the last point of one piece's rail) and q (the first of the next):
///   a convex corner, bridged as below (Sec. 6.1; p and q may lie on two faces
///   of the smooth body joined G1 at o); with the tangents t_a (arriving at o) and t_b
///   (leaving o) of C, convex means (q - p) . t_a > 0 and (q - p) . t_b > 0 (Fig. 12 (b)-(c));
/// - the gap side's rails cross instead ((q - p) . t_a < 0 and (q - p) . t_b < 0): a concave
///   corner, clipped and stitched (below; on two faces of the smooth body: Error (bad_input));
/// - neither side's rails meet (both bodies have an edge at o, the case Sec. 6.1 sets aside, or an
///   edge not perpendicular to the other face, whose rails would have to be clipped at the
///   edge: not done yet): Error (bad_input) naming the corner.
///
/// Step 2 (Sec. 6.1), the bridging fillet at a convex corner. The extracted text is garbled in
/// two places; what follows is the construction derived from the surrounding text and Fig. 12:
/// - Which rails have the gap. The text calls the body with the gap "T_1" and the corner "a C1
///   discontinuity of T_1 or T_2", and Fig. 12 (d) puts p and q on the cylinder, whose faces are
///   smooth at o, while the box has the edge. Indeed at a corner caused by an edge of body B
///   crossing the smooth face S of body A, the rails on B's two faces both end on the edge (at r,
///   |r - o| = d_B, when the edge is perpendicular to S), and the rails on S, offsets of the two
///   sides of a convex footprint corner, leave a gap. So the gap is on the smooth face S = S_g,
///   and the new fillet is "singular along the C0 discontinuity" of B: its face on B is the edge
///   segment o r.
/// - B_d. The text has "the locus of points on S_{1,m}, S_{1,m+1} at distance d from p"; with
///   d(o, p) = d(o, q) = d just above, it is the locus at distance d from o: B_d = S_g n
///   sphere(o, d), whose arc from p to q is the bridge's rail. It is traced here in the
///   half-planes through o spanned by S_g's normal n_o at o and m(phi) = slerp(p - o, q - o; phi),
///   phi in [0, 1]: Newton on |S_g(u, v) - o|^2 = d(phi)^2, (S_g(u, v) - o) . (n_o x m(phi)) = 0
///   (d(phi) runs linearly from |p - o| to |q - o|), continued from p; the (u, v) are interpolated
///   (cubic) with the parameter phi and checked halfway between samples against the tolerance.
/// - The fillet "between o and B_d": the sub-region on S_g is the fan S_g((1 - v) b(phi) + v o)
///   (Eqs. 2-3 with the intersection curve collapsed to o's parameters; composed or fitted,
///   fillet/compose.hpp), the one on B is the edge segment S_B((1 - v) o + v r) (constant in phi:
///   the singular face), and the blending surface the Hermite section of Alg. 1 between B_d(phi)
///   and r. Its tangents follow Sec. 1.3 as the neighbours' do: T_B = (r - o) / |r - o| (the
///   neighbours' T there is perpendicular to their rail in B's face, which is this direction
///   for both faces of the edge), and on S_g T = the projection of o - B_d(phi) (or its opposite
///   on side 2) onto S_g's tangent plane, normalised: B_d' is perpendicular to B_d - o (sphere)
///   and to n (surface), so that projection is perpendicular to B_d' in the tangent plane, as
///   Sec. 1.3's C^r' x N is; and at phi = 0, 1 it is the neighbours' T, because an offset rail
///   satisfies (R - C) . R' = 0 at its end. The lengths are tau |C_1 - C_2| as in Alg. 1. Hence
///   the bridge's cross-sections at phi = 0 and 1 are the neighbours' end sections, and the two
///   ruled halves (Alg. 2, fillet/ruled_fillet.hpp, properties by Sec. 7.1) glue C0 to them.
///   The control points of the section other than the rails are interpolated in phi at the
///   Greville points of the fan's knots, halved until within tolerance.
/// - Exact glue. Built alone, the bridge's end sections equal the neighbours' only to the fits'
///   tolerance (its fan and their sub-regions are fitted on different knots, its section is
///   interpolated where theirs comes from blending_surface: up to twice the tolerance apart on
///   the box and cylinder). fillet_across therefore pins them: per half, the bridge's and the
///   neighbour's cells are brought into one (v, w) space (exact), the neighbour's end layer takes
///   the bridge's singular rows (o, the segment o r and r, which the bridge holds the same in
///   every layer; the neighbour moves there by its own fit error), and the bridge's end layer of
///   control points becomes the neighbour's. The end faces are then one function, xyz and
///   properties: glue and property jump at rounding level (CornerQuality::glue, property_jump;
///   glue_before, property_jump_before: what pinning removed).
/// - B_d across a seam (Fig. 12 (d): p and q on two faces S_{1,2}, S_{1,3} of the smooth body,
///   joined G1). The gap's two ends lie on the arriving and the leaving piece's faces S_a, S_b;
///   then B_d crosses their shared boundary. The seam point s: on each boundary iso-curve c(t)
///   of S_a through o's parameters, the root of |c(t) - o| = d (d the mean of |p - o|, |q - o|)
///   on the side of o towards the gap (c'(t_o) . (p^ + q^) > 0; regula falsi from o); of those,
///   the one nearest S_b (closest point: s on S_b, their distance CornerQuality::seam_gap, within
///   the join tolerance, and the normals' angle seam_angle, within smooth_angle: else Error
///   (bad_input) naming both faces), and s must lie between p and q (the angles about o add
///   up). The bridge is then built per face, as two bridges of the construction above: part 0
///   from p to s on S_a, part 1 from s to q on S_b, each with its own fan to o on its face, the
///   edge segment o r, and the Hermite section, which at s is the same on both faces (it
///   depends only on s, o, r, the normal there and tau: G1 faces have one normal). So B_d, the
///   fan, G1 along B_d and det J > 0 inside hold part by part, exactly as for one face; part
///   0's end at p is pinned to the arriving piece, part 1's at q to the leaving one, and part 1's
///   end at s onto part 0's (as a stitch: no singular rows to carry, both hold o and r
///   exactly): seam_glue at rounding level (seam_glue_before: the two parts' own fits). Each
///   part's properties come from its own face, so a seam that is C0 in properties gives a
///   bridge C0 in properties (seam_property_jump). A fan across the seam (one cell for both
///   faces) would need a composition with a piecewise S_g, or a fit of both faces; one bridge
///   per face keeps every existing guarantee and the exact pinning.
///
/// Step 1b (Sec. 6, Fig. 12 (b)), the stitch at a concave corner. The text: "concave
/// discontinuities could be similarly handled ... while it would result with C1 discontinuities
/// on the fillet surface, along the trimmed location". Here: the crossing X of the two rails on
/// the shared face (Newton on rail_a(s) = rail_b(t) in its parameters, from the rails' ends at
/// o; crossing outside either piece: Error (bad_input)); the stitch plane Pi through o, X and r
/// (the other body's rails' common end on its edge). Each piece's two ruled halves are clipped
/// by Pi: their faces w = 0 (on S^_i) and w = 1 (on S_b) become F(u(s, v), v), u running from
/// a(v), where F's v-iso crosses Pi (a cubic interpolant of the roots, spans doubled until within
/// a tenth of the tolerance), to the far end (compose.hpp's sub-region of the ruled map, composed
/// or fitted to a quarter of the tolerance), and the half is ruled between them again (Alg. 2):
/// its end lies in Pi, its rail on S_g ends at X, on S^_i it ends on S_g's segment from X to o
/// (its other body's on the edge o r). The two clipped ends then coincide where the corner is
/// symmetric about Pi (a straight edge perpendicular to the face, equal distances: the blends
/// are mirror images and cross in Pi); elsewhere their distance exceeds the join tolerance:
/// Error (bad_input). Once every piece is clipped, the second piece's end is pinned onto the
/// first's (as the bridges are below, without singular rows): glue at rounding level
/// (Junction::glue, glue_before). The fillet surface is C0 there, with the C1 crease the text
/// announces. The clipped pieces' det J, volumes and shared-face glue are measured again; their
/// gaps to the faces and G1 angles are those of the unclipped fillets.
///
/// det J vanishes on the fan's edge at o and on the segment face (singular by construction, as
/// on the rails of every ruled fillet) and is checked at interior samples.
///
/// Cost: per pair one fillet_faces; per convex corner (per face of it) a few hundred surface
/// evaluations for B_d, one composition or fit, one interpolation per halving and one ruling (and
/// one closest-point set-up on the second face at a seam); the report samples a
/// few thousand points and closest points to the neighbours' end faces.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "trivox/fillet/fillet.hpp"

namespace trivox::fillet {

/// One face S_{k,i} of one body.
struct SideFace {
  const spline::Trivariate* cell = nullptr;  ///< in R^k; the same k on both sides
  spline::Face face = spline::Face::u0;
  std::string name;  ///< for messages and reports, e.g. "post.y1/u1"
};

struct CornerOptions {
  bool bridge = true;  ///< Sec. 6.1: bridge the convex corners (false: leave the gaps, Fig. 12 (c))
  /// How close the pieces' ends, and rails' ends, must be to count as one point (model units);
  /// <= 0: the larger of 100 fillet tolerances and 1e-4 of the smaller distance.
  double join_tolerance = 0.0;
  /// Junctions where C turns by at most this angle (rad) are G1 joins (smooth), whatever the
  /// small gap between their rails (faces that only approximate one smooth surface, such as the
  /// primitives' cubic circles, join with a slight kink); > 0.
  double smooth_angle = 1e-2;
};

/// One C_{i,j}: a component of S_{1,i} n S_{2,j} and its fillets.
struct FilletPiece {
  std::array<std::size_t, 2> face{};  ///< indices into side 1, side 2
  std::vector<Fillet> fillets;        ///< fillet_faces' fillets of this component, in order along C
  bool closed = false;
  /// The ends t = 0 and t = 1 of C_{i,j}: C there, the rails' ends on side 1 and 2 (xyz), the
  /// parameters of C and of the rails on both faces, and dC/dt.
  struct End {
    std::array<double, 3> o{}, tangent{};
    std::array<std::array<double, 3>, 2> rail{};
    std::array<std::array<double, 2>, 2> o_uv{}, rail_uv{};
  };
  std::array<End, 2> ends{};
};

/// smooth: a G1 join; corner: a convex corner, bridged (Sec. 6.1); stitch: a concave corner whose
/// rails on the smooth face cross, both pieces clipped at the stitch plane and stitched (Sec. 6).
enum class JunctionKind { smooth, corner, stitch };

/// Where two pieces meet: piece[0] arrives at o through its end end[0], piece[1] leaves it.
struct Junction {
  std::array<std::size_t, 2> piece{};
  std::array<int, 2> end{};
  JunctionKind kind = JunctionKind::smooth;
  double angle = 0.0;  ///< between C's tangents at o (rad): 0 where C is C1
  /// corner: the side (0: side 1) whose rails leave the gap (its face is smooth at o); the other
  /// side's rails meet at r
  int gap_side = -1;
  std::array<double, 3> o{}, p{}, q{}, r{};
  std::array<double, 2> rail_gap{};  ///< distance between the two pieces' rail ends, per side
  /// stitch: where the gap side's rails cross (X, the clipped rails' common end), the rails'
  /// parameters there (piece[0]'s, piece[1]'s), and the C0 glue between the two clipped ends
  /// after stitching (glue) and before (glue_before: their distance in the stitch plane)
  std::array<double, 3> x{};
  std::array<double, 2> crossing{};
  double glue = 0.0, glue_before = 0.0;
  std::array<spline::Face, 2> stitch_ends{};  ///< stitch: the clipped cells' ends (u0 or u1) at o
};

struct CornerQuality {
  double end_error = 0.0;     ///< max(|B(0) - p|, |B(1) - q|): the bridge's rail at its ends
  double radius_error = 0.0;  ///< max | |B(phi) - o| - d(phi) | at dense samples
  double o_error = 0.0;       ///< max distance of the fan's edge (the collapsed C) from o
  double r_error = 0.0;       ///< max distance of the blend's other rail from r
  double g1_angle = 0.0;      ///< max angle (rad) between S_b and S_g's tangent plane along B
  double det_min = 0.0, det_max = 0.0;  ///< det J at interior samples of both cells
  std::array<std::array<double, 2>, 2> cell_jacobian{};  ///< per cell: sampled det J min, max
  std::array<double, 2> cell_volume{};  ///< |int det J| per cell (divergence theorem)
  /// C0 glue: max xyz distance between the bridge's end faces (phi = 0, phi = 1) and the
  /// neighbouring pieces' end faces at the same (v, w), cell for cell, after fillet_across pinned
  /// them (rounding level; 0 from bridge_corner alone)
  std::array<double, 2> glue{};
  /// The same before pinning: how far the bridge's own fan fit and interpolated section ended
  /// from the neighbours' (their fits and blending surfaces); what the pinning moved the end
  /// layers by, in function values
  std::array<double, 2> glue_before{};
  /// Property jump across the glued ends: max |g_bridge - g_neighbour| (coordinates 3..k-1) on
  /// the end faces at the same (v, w), after and before pinning (0 without properties)
  std::array<double, 2> property_jump{}, property_jump_before{};
  /// A corner whose gap spans two faces of the smooth body (part >= 0, see CornerFillet): the
  /// seam point s = B_d n seam on the first face and on the second (xyz), their distance, the
  /// angle between the faces' normals there, and the C0 glue between the two parts' sections at
  /// s after pinning (xyz; properties) and before (the parts' own fits)
  std::array<std::array<double, 3>, 2> seam_point{};
  double seam_gap = 0.0, seam_angle = 0.0;
  double seam_glue = 0.0, seam_glue_before = 0.0, seam_property_jump = 0.0;
  std::array<int, 2> bd_samples{};  ///< samples of B_d; Greville rows of the section
  double seconds = 0.0;
  /// "positive", "negative" or "changes sign".
  std::string jacobian() const;
};

/// The bridging fillet at a convex corner: the two ruled halves (half 0 on side 1's sub-region,
/// half 1 on side 2's, as ruled_fillet returns them).
struct CornerFillet {
  std::size_t junction = 0;  ///< into MultiFillet::junctions
  std::array<spline::Trivariate, 2> cells;
  /// fillet_across: the cells' faces (u0 or u1) glued to the arriving piece (ends[0]) and to the
  /// leaving one (ends[1])
  std::array<spline::Face, 2> ends{spline::Face::u0, spline::Face::u1};
  /// -1: the whole bridge (the gap inside one face). 0, 1: the gap spans two faces, split at
  /// the seam point s: part 0 from p to s on the arriving piece's face (ends[1]: its end at s),
  /// part 1 from s to q on the leaving piece's (ends[0]: its end at s, pinned onto part 0's)
  int part = -1;
  CornerQuality quality;
};

/// What bridge_corner needs (see the file comment).
struct CornerInput {
  const spline::Surface* face = nullptr;  ///< S_g in R^k: the face the gap lies on, smooth at o
  int gap_side = 0;  ///< 0: S_g is the fillet's side 1 (its rail is rail 1, v = 0 of S_b); 1: side 2
  std::array<double, 2> o_uv{}, p_uv{}, q_uv{};  ///< on S_g: the corner o, the rails' ends p and q
  const spline::Surface* meet = nullptr;         ///< a face S_B of the other body through o, in R^k
  std::array<double, 2> meet_o_uv{}, meet_r_uv{};  ///< on S_B: o and the rails' common end r
};

/// Sec. 6.1: the singular fillet around o between p and q.
/// @param blend      the section: Hermite only, with its tau and angle tolerance
/// @param tolerance  B_d and the section's interpolation (model units), > 0
/// @throws Error (bad_input) for the flend section, p or q at o or opposite, B_d leaving S_g;
///         Error (failed) when Newton does not converge or the halvings do not reach the tolerance
CornerFillet bridge_corner(const CornerInput& input, const BlendOptions& blend, double tolerance,
                           const SubregionOptions& subregion = {});

struct MultiFillet {
  std::vector<FilletPiece> pieces;  ///< in order along C
  std::vector<Junction> junctions;  ///< in order along C; the last joins the last piece to the first when closed
  /// one per convex corner (CornerOptions::bridge); two (parts 0 and 1, adjacent) where the gap
  /// spans a seam between two faces
  std::vector<CornerFillet> corners;
  bool closed = false;              ///< the pieces form one closed loop
};

/// Sec. 6: the fillets between the faces of side 1 and side 2, over every pair that crosses along
/// a curve, chained at their ends; Sec. 6.1: the bridging fillets at the convex corners.
/// @throws Error (bad_input) for empty sides, no pair of faces crossing along a curve ("do not
///         intersect"), a pair fillet_faces refuses (the message names the pair), three pieces
///         meeting at one point, and the corners the file comment lists (named by o and the
///         pieces); the errors of fillet_faces and bridge_corner
MultiFillet fillet_across(const std::vector<SideFace>& side1, const std::vector<SideFace>& side2,
                          const FilletOptions& options, const CornerOptions& corners = {});

}  // namespace trivox::fillet
