/// @file src/fillet/corner_util.hpp
/// @brief Private to the fillet module: what the files of the fillet over several faces share
/// (trivox/fillet/corners.hpp; Masalha et al. 2021, Sec. 6 and 6.1). Points in messages, the
/// bridge's cells measured (corner_fillet.cpp), the C0 glue between end sections, measured and
/// pinned (corner_glue.cpp), the concave corner's crossing and clipping (corner_stitch.cpp), and
/// the seam point of B_d (corner_seam.cpp).
#pragma once
#include <array>
#include <span>
#include <string>
#include <vector>

#include "fillet_util.hpp"
#include "trivox/fillet/corners.hpp"
#include "trivox/spline/extract.hpp"

namespace trivox::fillet::detail {

/// "(x, y, z)", for messages (corners.cpp).
std::string at(const Vec& p);

/// The xyz of s at uv.
inline Vec point_at(const spline::Surface& s, const std::array<double, 2>& uv) { return xyz(s.eval({uv[0], uv[1]})); }

// ---- the bridge at a convex corner (corner_fillet.cpp; Sec. 6.1) ----

/// The bridge's cells: sampled det J and volumes.
void measure_cells(CornerFillet& cf);

// ---- the C0 glue between end sections (corner_glue.cpp) ----

/// Largest xyz distance, and largest property difference (coordinates 3..k-1), between two faces
/// at the same relative parameters (13 x 13 samples).
std::array<double, 2> face_gaps(const spline::Surface& a, const spline::Surface& b);

/// Makes the singular rows exactly the same in every layer along phi (the middle layer's): the
/// fan's and the segment's fits hold them constant only to rounding.
void exact_singular_rows(std::array<spline::Trivariate, 2>& cells, std::size_t gs);

/// Pins the bridge's end face `end` (u0 or u1) onto the neighbour's end face `nb_end`, half for
/// half: each pair of cells is brought into one (v, w) function space (exact: knot insertion and
/// degree raising), the neighbour's end layer takes the bridge's singular rows (it moves there by
/// its fit's error: its C end, its edge segment and r), and the bridge's end layer becomes the
/// neighbour's. The faces are then one function, so the C0 glue of Sec. 6.1 holds to rounding,
/// whatever the neighbour's fit and the bridge's interpolated section differed by, and the
/// bridge keeps its exact singular structure (det J = 0 on the collapsed edges, not slightly
/// negative). The change fades out over the first knot span along phi.
/// With gs < 0 (a stitch: no singular rows) the neighbour is left as it is.
void pin_end(std::span<spline::Trivariate> cells, int gs, spline::Face end, std::span<spline::Trivariate> nb,
             spline::Face nb_end);

// ---- the concave corner (corner_stitch.cpp; Sec. 6) ----

/// Where two rails on one face cross: s on ra, t on rb (both in the face's parameters), by
/// Newton on ra(s) = rb(t) from (s0, t0), the rails' ends at the corner. False when it does not
/// converge inside both domains.
bool rails_cross(const spline::Curve& ra, const spline::Curve& rb, double& s, double& t);

/// Masalha et al. 2021, Sec. 6, the concave corner: a ruled fillet half clipped by the stitch plane
/// Pi (through o, n its normal): each of its faces w = 0 (on S^_i) and w = 1 (on S_b) becomes
/// F(u(s, v), v), u running from where F's v-iso crosses Pi (a(v), interpolated at the Greville
/// points of a cubic space, spans doubled until F(a(v), v) is within tol of Pi) to the far end
/// (fillet/compose.hpp's sub-region with the ruled map between (a(v), v) and (u_far, v):
/// composed, or fitted to tol), and the cell is ruled between them again (Alg. 2): the cut
/// rulings from the clipped S^_i to the clipped S_b lie in Pi at s = 0. `end` is the cell's end at
/// the corner (u0 or u1); the result keeps u's direction.
spline::Trivariate clip_half(const spline::Trivariate& h, spline::Face end, const Vec& o, const Vec& n, double side,
                             double tol);

/// A clipped or stitched piece's fillet: det J at interior samples, volumes and the halves' glue
/// again (the gaps to the faces, the G1 angle and the property jump stay those of the unclipped
/// fillet, of which the clipped cells are the part beyond the stitch plane, refitted to a quarter
/// of the tolerance).
void remeasure(Fillet& fl);

// ---- a gap across a seam (corner_seam.cpp; Fig. 12 (d)) ----

/// Where B_d (radius d about o) crosses the boundaries of s through o: for every boundary
/// iso-curve c of s that holds o's parameters o_uv, the root of |c(t) - o| = d on the side of o
/// where c runs towards `into` (the gap), by regula falsi from o. None where c leaves s first.
std::vector<std::array<double, 2>> seam_crossings(const spline::Surface& s, const std::array<double, 2>& o_uv, const Vec& o,
                                                  const Vec& into, double d);

}  // namespace trivox::fillet::detail
