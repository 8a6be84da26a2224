// The slow path for one voxel (voxel_solve.hpp): damped Newton over the cell from a prediction
// (six iterations), then each leaf whose row interval holds the voxel, warm-started from its own
// answer at the previous voxel (Locator::solve_in_leaf, with its subdivision fallback); when
// some run fails, the best iterate decides (inside when its image is within half the smallest
// pitch). Cost: a few Newton iterations, O(o^3) each, per leaf tried.
#include "voxel_solve.hpp"

#include <algorithm>
#include <limits>

namespace trivox::slice::detail {

Outcome solve_voxel(const Locator& loc, const VoxelGrid& grid, int cell, int i, const Vec3& p, const Vec3* start,
                    Chain& chain, Vec3& t, RowLeaf* leaves_begin, RowLeaf* leaves_end, const std::array<Vec3, 2>& dom,
                    std::int64_t& failures) {
  NewtonResult res;
  if (start) res = loc.newton(cell, p, *start, dom[0], dom[1], 6);
  if (!start || res.status != NewtonStatus::converged) {
    const Vec3 from = res.uvw;
    NewtonResult best;
    best.residual = std::numeric_limits<double>::infinity();
    bool failed = false, found = false;
    for (RowLeaf* rl = leaves_begin; rl != leaves_end; ++rl) {
      if (i < rl->i0 || i > rl->i1) continue;
      const Vec3* warm = rl->last_i == i - 1 ? &rl->last_t : start ? &from : nullptr;
      const NewtonResult lr = loc.solve_in_leaf(rl->leaf, p, warm);
      rl->last_i = i;
      rl->last_t = lr.polished;
      if (lr.status == NewtonStatus::converged) {
        res = lr;
        found = true;
        break;
      }
      if (lr.status == NewtonStatus::failed) {
        failed = true;
        if (lr.residual < best.residual) best = lr;
      }
    }
    if (!found) {
      chain.n = 0;
      if (!failed) return Outcome::outside;
      ++failures;
      // Best guess: inside when the best iterate's image is within half the smallest pitch.
      const double guess = 0.5 * std::min({grid.pitch[0], grid.pitch[1], grid.pitch[2]});
      if (!(best.residual < guess)) return Outcome::outside;
      t = best.uvw;
      return Outcome::guessed;
    }
  }
  t = res.uvw;
  chain.push_solved(res);
  return Outcome::inside;
}

}  // namespace trivox::slice::detail
