/// @file trivox/vmodel/shepard_field.hpp
/// @brief The Euclidean-distance (Shepard) property field of a fillet: the exact blend f that
/// fillets encode (fillet/shepard.hpp) and the slicer evaluates per voxel (slice/sampler.hpp).
///
/// Masalha, Cirillo & Elber 2021, Sec. 7.2, after Biswas et al. 2004 and Shepard
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
/// there when g_1 != g_2 on C (Masalha et al. 2021, Sec. 7.1 notes the same of the parametric
/// blend); there trivox takes alpha_1 = alpha_2 = 1/2. Elsewhere f is continuous (C^q away from the
/// points where a closest point jumps).
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
/// evaluation with second partials of S^_i) and two evaluations.
#pragma once
#include <array>
#include <cstdint>

#include "trivox/geom/closest_point.hpp"
#include "trivox/spline/tensor_spline.hpp"
#include "trivox/vmodel/vmodel.hpp"

namespace trivox::vmodel {

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

}  // namespace trivox::vmodel
