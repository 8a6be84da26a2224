/// @file src/slice/voxel_solve.hpp
/// @brief (private to src/slice) A voxel off the certified runs: the warm starts extrapolated
/// from the last converged voxels of a run (Chain, inline: asked per voxel), and the exact slow
/// path, Newton from a prediction then the leaves that hold the voxel (solve_voxel, in
/// voxel_solve.cpp).
#pragma once
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>

#include "trivox/slice/grid.hpp"
#include "trivox/slice/locator.hpp"

#include "mat3.hpp"
#include "row_leaf.hpp"

namespace trivox::slice::detail {

/// The last converged voxels of a run in one cell, for extrapolating the next voxel's (u,v,w)
/// where stepping does not apply (rational cells, many properties): their uvw corrected to well
/// below the tolerance (extrapolation amplifies errors), and the inverse Jacobian of the last
/// Newton run for those corrections.
struct Chain {
  Vec3 uvw[3] = {};
  int n = 0;
  std::array<Vec3, 3> inv{};
  bool have_inv = false;

  /// Quadratic (linear, constant) extrapolation; false when it leaves the domain.
  bool predict(const std::array<Vec3, 2>& dom, Vec3& t) const {
    for (std::size_t d = 0; d < 3; ++d) {
      t[d] = n == 1 ? uvw[0][d] : n == 2 ? 2.0 * uvw[0][d] - uvw[1][d] : 3.0 * uvw[0][d] - 3.0 * uvw[1][d] + uvw[2][d];
      if (t[d] < dom[0][d] || t[d] > dom[1][d]) return false;
    }
    return true;
  }
  void push(const Vec3& t) {
    uvw[2] = uvw[1];
    uvw[1] = uvw[0];
    uvw[0] = t;
    n = std::min(n + 1, 3);
  }
  /// A voxel accepted at t with residual r = p - X(t): a quasi-Newton step with the last
  /// Jacobian (a few voxels away, so close) before remembering it.
  void push_checked(Vec3 t, const Vec3& r, const std::array<Vec3, 2>& dom) {
    if (have_inv) {
      const Vec3 c = mul(inv, r);
      for (std::size_t d = 0; d < 3; ++d) t[d] = std::clamp(t[d] + c[d], dom[0][d], dom[1][d]);
    }
    push(t);
  }
  void push_solved(const NewtonResult& res) {
    have_inv = invert(res.jacobian, inv);
    push(res.polished);
  }
  void set_jacobian(const std::array<Vec3, 3>& jac) { have_inv = invert(jac, inv); }
};

enum class Outcome { inside, guessed, outside };

/// The slow path for one voxel: Newton over the cell from a prediction (when there is one), then
/// the leaves whose intervals hold the voxel, each warm-started from its own answer at the
/// previous voxel (Locator::solve_in_leaf, with its subdivision fallback).
/// @param start        a prediction, or null
Outcome solve_voxel(const Locator& loc, const VoxelGrid& grid, int cell, int i, const Vec3& p, const Vec3* start,
                    Chain& chain, Vec3& t, RowLeaf* leaves_begin, RowLeaf* leaves_end, const std::array<Vec3, 2>& dom,
                    std::int64_t& failures);

}  // namespace trivox::slice::detail
