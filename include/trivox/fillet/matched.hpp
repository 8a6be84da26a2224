/// @file trivox/fillet/matched.hpp
/// @brief Fillets between B-spline primary surfaces as matched Bezier pairs: the intersection
/// curve and the rails cut where iso-parametric lines of either face cross them, so that every
/// piece of each sub-region lies in one polynomial piece of its face and is composed exactly.
///
/// Masalha, Cirillo & Elber 2021, Sec. 4.1-4.2:
/// - Subdivision values (Alg. 4): every interior knot line of S_i (u = u_0 or v = v_0) that the
///   intersection curve crosses in S_i's parameters, at C(t_0) (Eq. 6: u^{S_i}(t_0) = u_0, all
///   roots), gives S_j an iso-line through c^{S_j}(t_0) as well, the one "most orthogonal to"
///   C there (the text of Sec. 4.1 and Fig. 7). The iso-line u = const runs along S_v, so it is
///   the more orthogonal one when |<d_v, d_c>| < |<d_u, d_c>|; Alg. 4's line 21 as extracted
///   reads the other way round (u-value when |<d_u, d_c>| < |<d_v, d_c>|), which picks the line
///   more nearly parallel to C: on a plane meeting a cylinder (the lamp's base and rod) that line
///   crosses C twice near the tangency and misses the rail, failing Lemma 1, where the
///   orthogonal one cuts the strip cleanly. The text's rule is implemented (AddSubdivVal).
/// - Verify (Alg. 5 line 15, Lemma 1): each iso-line that is cut along crosses the intersection
///   curve as many times as the face's rail; otherwise the sub-regions of the two faces cannot be
///   matched piece for piece, and this construction fails (Error failed, naming the line): Sec.
///   4.3's fitting applies instead (SubregionMethod::fit).
/// - Split (Definition 4.1) and matching: the k-th crossing of such a line with C is paired with
///   its crossing of the rail nearest along the curve, which splits the rail there. Piece p of
///   the fillet runs along C from t_p to t_{p+1} and along rail i from r_{i,p} to r_{i,p+1};
///   its boundary between pieces is, on each face, a segment of the iso-line from C to the rail,
///   so the sub-region pieces (ruled surfaces in the face's parameters between the reparametrised
///   pieces of c^{S_i} and c_i^r, Masalha et al. 2021 Eqs. 2-3) stay inside
/// one Bezier patch and compose
///   exactly (compose.hpp). Neighbouring pieces share that boundary, the blending surfaces
///   interpolate the same end points with the same tangent fields, so the fillets of Alg. 5's
///   line 20 (BzrFillet, Alg. 2) join continuously.
/// A closed intersection curve is also cut at t = 0 (= 1), where all four curves share their
/// parameter: the join there is a ruling, not an iso-line, like the ends of an open curve.
///
/// Cost: per knot line one root search along the four curves (32 samples per span, then
/// bisection to 1e-15 of the domain); then one exact composition per piece and face.
#pragma once
#include <array>
#include <vector>

#include "trivox/fillet/blend_surface.hpp"
#include "trivox/fillet/rails.hpp"
#include "trivox/spline/tensor_spline.hpp"

namespace trivox::fillet {

/// One cut across the fillet, at C(t) (Alg. 4's subdivision value and its matches).
struct MatchedCut {
  double t = 0.0;                  ///< on C (and the base curves)
  std::array<double, 2> rail{};    ///< where face i's cutting line crosses rail i
  std::array<int, 2> dir{};        ///< face i's cutting line: 0 for u = value, 1 for v = value
  std::array<double, 2> value{};   ///< its parameter value
  std::array<bool, 2> knot{};      ///< it is a knot line of face i (else added by AddSubdivVal)
};

/// The cuts, sorted by t, strictly inside (0, 1); empty when C crosses no knot line of either
/// face (then one exact composition covers the whole fillet).
/// @throws Error (failed) when a cutting line crosses C and its face's rail different numbers of
///         of times (Lemma 1), or the rail crossings do not follow C's order (the message names
///         the face, the line and the counts, and says that method "fit" applies)
std::vector<MatchedCut> matched_cuts(const spline::Surface& face1, const spline::Surface& face2, const RailPair& rails);

/// One Bezier pair of Alg. 5: the exact sub-regions and the blending surface's input.
struct MatchedPiece {
  std::array<double, 2> t{};                     ///< range on C
  std::array<std::array<double, 2>, 2> rail{};   ///< range on rail i
  spline::Surface sub1, sub2;                    ///< as fillet_faces' (v = 0 on rail 1 / on C)
  BlendInput blend;                              ///< for blending_surface (faces point to the inputs)
};

/// The pieces between consecutive cuts (and the ends, or t = 0 = 1 for a closed C).
/// @throws Error (failed) as matched_cuts, or when a piece's sub-region still crosses a knot
///         line of its face (the ruling from C to the rail leaves the patch)
std::vector<MatchedPiece> matched_pieces(const spline::Surface& face1, const spline::Surface& face2, const RailPair& rails,
                                         const std::vector<MatchedCut>& cuts);

}  // namespace trivox::fillet
