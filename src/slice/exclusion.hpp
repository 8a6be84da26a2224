/// @file src/slice/exclusion.hpp
/// @brief (private to src/slice) Proving without Newton that a voxel whose predicted parameters
/// leave a cell's domain is not in the cell's leaves near that face: one expansion at the face
/// (Locator::expand) and a Taylor bound on where a root could lie. Inline: the block sampler
/// tries its last few proofs at every such voxel. Cost: set O(1) (the piece's bounds computed
/// on first use), proves O(1) plus a pass over the row's leaves that hold the voxel.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>

#include "trivox/slice/locator.hpp"

#include "mat3.hpp"
#include "row_leaf.hpp"

namespace trivox::slice::detail {

/// A proof that points beyond a face of a cell are not in the leaves of one Bezier piece near
/// that face, from one expansion at a point tb on the face (where the voxels' linear-model
/// parameters leave the domain), without Newton. With c = J0^-1 (p - X(tb)) and the piece's
/// bounds on second partials (StepBounds::b2v, seen through |J0^-1| entrywise: W_j bounds the
/// j-th component of J0^-1 d^2X / dt_d dt_e summed over d, e), a root t* of X(t) = p at
/// s = |t* - tb|_inf satisfies s <= |c|_inf + W s^2 / 2 (Taylor along the segment from tb, which
/// stays where the bounds hold), so s <= s1 = 2 |c| / (1 + sqrt(1 - 2 W |c|)) or s >= s2 =
/// (1 + sqrt(1 - 2 W |c|)) / W. A leaf of the piece within the bounds' box and closer to tb
/// than s2 (in every direction) can hold a root only within s1 of tb, and there
/// t*_j - tb_j >= c_j - W_j s1^2 / 2 (or <= c_j + W_j s1^2 / 2): when that puts t*_j beyond the
/// domain's face that tb lies on, the leaf holds no root, and p is not in it.
struct Exclusion {
  int piece = -1;               ///< -1: unused
  Vec3 tb{}, xb{};              ///< the expansion point and X(tb)
  std::array<Vec3, 3> inv{};    ///< J0^-1, rows
  std::array<int, 3> side{};    ///< +1: tb on the domain's upper face along j; -1 lower; 0 neither
  Vec3 wj{};                    ///< W_j
  double w = 0.0;               ///< max_j W_j
  Vec3 lo{}, hi{};              ///< where the bounds hold
  double margin = 0.0;          ///< parameter margin beyond the face (rounding)

  /// From an expansion at tb = e.t (t clamped to the domain `dom`, the prediction t beyond it).
  bool set(const Locator& loc, const Expansion& e, const std::array<Vec3, 2>& dom) {
    piece = -1;
    bool any = false;
    for (std::size_t j = 0; j < 3; ++j) {
      side[j] = e.t[j] >= dom[1][j] ? 1 : e.t[j] <= dom[0][j] ? -1 : 0;
      any = any || side[j] != 0;
    }
    if (!any || !invert(e.jac, inv)) return false;
    const StepBounds& b = loc.step_bounds(e.piece);
    if (!b.valid) return false;
    w = 0.0;
    for (std::size_t j = 0; j < 3; ++j) {
      double sum = 0.0;
      for (std::size_t d = 0; d < 3; ++d)
        for (std::size_t f = 0; f < 3; ++f)
          sum += std::abs(inv[j][0]) * b.b2v[d][f][0] + std::abs(inv[j][1]) * b.b2v[d][f][1] + std::abs(inv[j][2]) * b.b2v[d][f][2];
      wj[j] = sum * (1.0 + 1e-12);
      w = std::max(w, wj[j]);
    }
    if (!std::isfinite(w)) return false;
    lo = b.lo;
    hi = b.hi;
    margin = 0.0;
    for (std::size_t j = 0; j < 3; ++j) margin = std::max(margin, 1e-12 * (std::abs(dom[0][j]) + std::abs(dom[1][j])));
    tb = e.t;
    xb = e.x;
    piece = e.piece;
    return true;
  }

  /// Whether p lies in none of the leaves [lb, le) that hold voxel i (their row intervals).
  bool proves(const Vec3& p, int i, const RowLeaf* lb, const RowLeaf* le, std::span<const LocatorLeaf> leaves) const {
    if (piece < 0) return false;
    const Vec3 r{p[0] - xb[0], p[1] - xb[1], p[2] - xb[2]};
    const Vec3 c = mul(inv, r);
    const double cn = std::max({std::abs(c[0]), std::abs(c[1]), std::abs(c[2])});
    const double disc = 1.0 - 2.0 * w * cn;
    if (!(disc > 0.0)) return false;
    const double sq = std::sqrt(disc);
    const double s1 = 2.0 * cn / (1.0 + sq);
    const double s2 = w > 0.0 ? (1.0 + sq) / w : std::numeric_limits<double>::infinity();
    bool beyond = false;
    for (std::size_t j = 0; j < 3 && !beyond; ++j) {
      const double q = 0.5 * wj[j] * s1 * s1 + margin;
      beyond = (side[j] > 0 && c[j] > q) || (side[j] < 0 && c[j] < -q);
    }
    if (!beyond) return false;
    for (const RowLeaf* rl = lb; rl != le; ++rl) {
      if (i < rl->i0 || i > rl->i1) continue;
      const LocatorLeaf& lf = leaves[static_cast<std::size_t>(rl->leaf)];
      if (lf.piece != piece) return false;
      for (std::size_t j = 0; j < 3; ++j)
        if (lf.lo[j] < lo[j] - margin || lf.hi[j] > hi[j] + margin || !(std::max(lf.hi[j] - tb[j], tb[j] - lf.lo[j]) < s2)) return false;
    }
    return true;
  }
};

}  // namespace trivox::slice::detail
