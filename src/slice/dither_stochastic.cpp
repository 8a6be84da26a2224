/// @file src/slice/dither_stochastic.cpp
/// @brief Stochastic dithering along one row: each voxel's material drawn by inverse CDF from a
/// uniform number hashed (mix64) from the row's key and the voxel's column, so that the pattern
/// is independent of banding, threads and visiting order. LayerDitherer::stochastic_row derives
/// the key from (seed, layer, row).
///
/// Cost: O(materials) per voxel (two passes over its fractions without branches: their total,
/// then the cumulative sums compared with the target) and one 64-bit hash; O(1) per void voxel.
/// No allocation.
#include <cstdint>

#include "dither_kernels.hpp"
#include "trivox/slice/material.hpp"

namespace trivox::slice::detail {

namespace {

/// Inverse CDF without branches: the chosen index is the number of cumulative sums at or
/// below the target, which skips zero fractions (their cumulative sum equals the previous
/// one) and never picks one.
template <int MC>
void stochastic_kernel(int nx, int materials, std::uint64_t key, const std::int32_t* cell, const float* fractions,
                       std::uint8_t* out) {
  const int m = MC > 0 ? MC : materials;
  for (int x = 0; x < nx; ++x) {
    if (cell[x] < 0) {
      out[x] = void_material;
      continue;
    }
    const float* f = fractions + static_cast<std::ptrdiff_t>(x) * m;
    float total = 0.0f;
    for (int k = 0; k < m; ++k) total += f[k] > 0.0f ? f[k] : 0.0f;
    // 24 random bits: a uniform float in [0, 1).
    const float u = static_cast<float>(mix64(key ^ static_cast<std::uint32_t>(x)) >> 40) * 0x1p-24f;
    const float target = u * total;
    float cumulative = 0.0f;
    int chosen = 0;
    for (int k = 0; k < m; ++k) {
      cumulative += f[k] > 0.0f ? f[k] : 0.0f;
      chosen += cumulative <= target;
    }
    if (chosen >= m) {  // rounding put the target at the top (or no fraction is positive)
      chosen = 0;
      for (int k = 0; k < m; ++k) chosen = f[k] > 0.0f ? k : chosen;
    }
    out[x] = static_cast<std::uint8_t>(chosen);
  }
}

}  // namespace

StochasticKernel stochastic_kernel_for(int materials) {
  switch (materials) {
    case 1: return stochastic_kernel<1>;
    case 2: return stochastic_kernel<2>;
    case 3: return stochastic_kernel<3>;
    case 4: return stochastic_kernel<4>;
    case 5: return stochastic_kernel<5>;
    case 6: return stochastic_kernel<6>;
    case 7: return stochastic_kernel<7>;
    case 8: return stochastic_kernel<8>;
    default: return stochastic_kernel<0>;
  }
}

}  // namespace trivox::slice::detail
