// The exact Shepard blend on a sampled block (LayerSampler::apply_shepard, sampler.hpp;
// Masalha et al. 2021, Sec. 7.2; vmodel/shepard_field.hpp): f at the centre of every voxel held
// by a cell with Shepard data, each field's closest-point walks warm-started from the nearest of
// a few walks of the block (within eight pitches), so a voxel's value depends only on its block.
// Cost: two closest-point queries per such voxel, a few iterations each when warm.
#include "trivox/slice/sampler.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

namespace trivox::slice {

void LayerSampler::apply_shepard(int layer, int r0, int nr, std::int32_t* owner, float* props) const {
  const int nx = grid_.count[0], ny = grid_.count[1];
  const auto m = static_cast<std::size_t>(locator_.model().properties.size());
  // Per field a few walks, each the state at its last point: a voxel starts from the walk whose
  // last point is nearest (the previous voxel of the row, or the voxel above it in the previous
  // row, or the other side of a gap), a new walk (cold) when none is within `reach`. All state
  // is local to the block, so a voxel's value depends only on its block.
  constexpr std::size_t slots = 4;
  const double reach = 8.0 * std::max({grid_.pitch[0], grid_.pitch[1], grid_.pitch[2]});
  std::vector<std::array<vmodel::ShepardWalk, slots>> walks(shepard_.size());
  std::vector<std::int64_t> used(shepard_.size() * slots, 0);  // last use of each walk, per field
  std::vector<double> f(m);
  std::int64_t voxels = 0, warm = 0;
  for (int r = 0; r < nr; ++r) {
    const int j = ny - 1 - (r0 + r);  // image row -> grid row (grid.hpp)
    for (int i = 0; i < nx; ++i) {
      const std::size_t v = static_cast<std::size_t>(r) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(i);
      const int c = owner[v];
      if (c < 0) continue;
      const int k = shepard_of_[static_cast<std::size_t>(c)];
      if (k < 0) continue;
      const auto p = grid_.centre(i, j, layer);
      auto& ws = walks[static_cast<std::size_t>(k)];
      std::int64_t* age = used.data() + static_cast<std::size_t>(k) * slots;
      std::size_t best = slots, oldest = 0;
      double bd = reach;
      for (std::size_t s = 0; s < slots; ++s) {
        if (age[s] < age[oldest]) oldest = s;
        if (!ws[s].valid) continue;
        const double d = std::hypot(p[0] - ws[s].p[0], p[1] - ws[s].p[1], p[2] - ws[s].p[2]);
        if (d < bd) bd = d, best = s;
      }
      if (best == slots) {  // cold, in the least recently used slot
        best = oldest;
        ws[best].valid = false;
      }
      age[best] = ++voxels;
      shepard_[static_cast<std::size_t>(k)]->eval(p, f.data(), &ws[best]);
      std::transform(f.begin(), f.end(), props + v * m, [](double x) { return static_cast<float>(x); });
    }
  }
  for (const auto& ws : walks)
    for (const auto& w : ws) warm += w.warm;
  shepard_voxels_ += voxels;
  shepard_warm_ += warm;
}

}  // namespace trivox::slice
