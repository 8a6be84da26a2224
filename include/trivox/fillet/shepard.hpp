/// @file trivox/fillet/shepard.hpp
/// @brief Euclidean-distance (Shepard) property blending of fillets: the exact blend f and its
/// least-squares encoding into a fillet half's control points.
///
/// Masalha, Cirillo & Elber 2021 (seed 000), Sec. 7.2, after Biswas et al. 2004 and Shepard
/// 1968. For p in the fillet, with d_i(p) the distance from p to the fillet's sub-region S^_i
/// (its face on primary surface S_i), pi_i(p) the closest point's parameters and g_i the
/// properties S^_i carries,
///
///     alpha_i(p) = d_i^-q / (d_1^-q + d_2^-q),   f(p) = alpha_1 g_1(pi_1(p)) + alpha_2 g_2(pi_2(p)),
///
/// q a positive integer. The weights are computed as alpha_1 = 1 / (1 + (d_1 / d_2)^q) when
/// d_1 <= d_2, alpha_2 = t / (1 + t) with t = (d_1 / d_2)^q (and symmetrically): no division by
/// zero on S^_i, where
/// alpha_i = 1 exactly (Eq. 9a, feature preservation), alpha_1 + alpha_2 = 1 (Eq. 9b) and both in
/// [0, 1] (Eq. 9c). On the intersection curve C both distances vanish and f is not continuous
/// there when g_1 != g_2 on C (seed 000 Sec. 7.1 notes the same of the parametric blend); there
/// trivox takes alpha_1 = alpha_2 = 1/2. Elsewhere f is continuous (C^q away from the points where
/// a closest point jumps).
///
/// Encoding (Sec. 7.2: "evaluating f in a user-controlled number of sampled points in the domain
/// of T, and solving a least-square-fitting problem ... fix ... the points at the boundaries"):
/// the half's properties become G + R, G(u, v) its own properties on the face w = 0 (S^_i with
/// g_i, copied along w) and R a tensor-product spline in a fit space (the half's u and v spaces,
/// or for many control points order 4 on at most `max_spans` of its breakpoints; v with knots
/// graded towards both ends, one of them C, where f turns fastest; along w order 4 with `w_spans`
/// spans graded towards w = 0) whose control points at w = 0 are pinned to zero, fitted by
/// least squares to f - G at Gauss points of every span (a full tensor grid, so the least
/// squares solution is the Kronecker product of the three 1-D pseudo-inverses). Half and R are
/// then brought into one space (spline::make_compatible); the control points of the face w = 0
/// are the half's own, bit for bit, so the encoded properties equal g_i exactly on S^_i.
///
/// Closest points: geom::SurfaceDistance on S^_1 and S^_2, warm-started along a walk of nearby
/// points (ShepardWalk): Newton from the previous point's (u, v), accepted when it settles and
/// its distance obeys the 1-Lipschitz bound d(p) <= d(p') + |p - p'| (else a cold query). The
/// warm answer is the cold one to rounding when both starts lie in the global minimum's basin
/// (points that move little against the faces' curvature radius); not certified beyond the
/// Lipschitz test. Results depend only on the walk's sequence of points, so callers that fix
/// the sequence (one walk per sampler block row, the fit's per-sample-column walks) get the same
/// bytes for any thread count.
///
/// Cost: f at one point: two closest-point queries (warm: two or three Newton steps, each one
/// evaluation with second partials of S^_i) and two evaluations. Encoding: one f per sample,
/// about (2 n_u) x (2 n_v) x (2 n_w) samples for a fit space of n_u x n_v x n_w, and as many
/// again at midpoints for the check, in parallel.
#pragma once
#include <array>
#include <cstdint>

#include "trivox/geom/closest_point.hpp"
#include "trivox/spline/tensor_spline.hpp"
#include "trivox/vmodel/vmodel.hpp"

namespace trivox::fillet {

/// alpha_1, alpha_2 for distances d_1, d_2 >= 0 and power q >= 1 (see the file comment; both
/// zero: 1/2 each).
std::array<double, 2> shepard_weights(double d1, double d2, int q) noexcept;

/// The warm-start state of a walk over nearby points: one per thread and sequence of points.
struct ShepardWalk {
  bool valid = false;                          ///< false: the next query is cold
  std::array<double, 3> p{};                   ///< the previous point
  std::array<std::array<double, 2>, 2> uv{};   ///< its closest points' parameters on S^_1, S^_2
  std::array<double, 2> d{};                   ///< and distances
  std::int64_t warm = 0, cold = 0;             ///< queries answered warm / cold (cost figures)
};

/// What f(p) was made of.
struct ShepardValue {
  std::array<double, 2> alpha{};                ///< alpha_1, alpha_2
  std::array<double, 2> distance{};             ///< d_1, d_2
  std::array<std::array<double, 2>, 2> uv{};    ///< pi_1(p), pi_2(p)
};

/// The exact blend f of one fillet: S^_1, S^_2 prepared for closest points, and q.
class ShepardField {
public:
  /// @param sources  S^_1, S^_2 in R^(3+m), the same m (xyz then the properties g_i)
  /// @param power    q, 1..16
  /// @throws Error (bad_input) for other dimensions, fewer than 3 coordinates or q out of range
  ShepardField(const std::array<spline::Surface, 2>& sources, int power);
  explicit ShepardField(const vmodel::ShepardData& data) : ShepardField(data.sources, data.power) {}

  /// f(p): properties() values into `props`. Cold closest points without a walk (or with an
  /// invalid one); with a walk, warm-started from it, which is then updated. Thread-safe (the
  /// walk is the caller's).
  ShepardValue eval(const std::array<double, 3>& p, double* props, ShepardWalk* walk = nullptr) const;

  int properties() const noexcept { return m_; }
  int power() const noexcept { return q_; }
  const geom::SurfaceDistance& source(int i) const noexcept { return dist_[static_cast<std::size_t>(i)]; }

private:
  std::array<geom::SurfaceDistance, 2> dist_;
  int m_ = 0, q_ = 2;
  double slack_ = 0.0;  ///< rounding allowance of the Lipschitz test (model units)
};

struct ShepardOptions {
  int power = 2;       ///< q, 1..16
  int w_spans = 4;     ///< spans of the fit space along w, graded towards w = 0: 2^-k (1..16)
  int grade = 2;       ///< v: knots 1/2, 2^-k and 1 - 2^-k for k = 2..grade + 1 added (0: none)
  int w_order = 4;     ///< order of the fit space along w (2..8)
  int max_spans = 64;  ///< u or v: at most this many spans of the half's breakpoints in the fit
  int max_direct = 24; ///< u or v with at most this many control points: the half's own space
};

/// The encoded half and how well it reproduces f.
struct ShepardEncoding {
  spline::Trivariate half;   ///< the half, its properties G + R (geometry unchanged, w refined)
  double max_error = 0.0;    ///< max |encoded - f| over the samples, all properties
  double rms_error = 0.0;    ///< root mean square of the same
  double check_error = 0.0;  ///< max |encoded - f| at the midpoints between samples (a check)
  std::int64_t samples = 0;  ///< points where f was evaluated for the fit
  std::array<int, 3> fit_counts{};  ///< control points of R per direction (w's first pinned)
  double seconds = 0.0;
};

/// Encodes f into a fillet half by least squares, the half's face w = 0 pinned (file comment).
/// @param half     a fillet half (ruled_fillet.hpp) in R^(3+m): w = 0 on S^_i, w = 1 on S_b
/// @param field    f, over the same properties
/// @throws Error (bad_input) for a rational half, other dimensions or options out of range
ShepardEncoding encode_shepard(const spline::Trivariate& half, const ShepardField& field,
                               const ShepardOptions& options = {});

}  // namespace trivox::fillet
