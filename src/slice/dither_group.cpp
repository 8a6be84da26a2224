/// @file src/slice/dither_group.cpp
/// @brief LayerGroupDitherer: error diffusion of up to eight layers at once on the print job's
/// colour path (trivox/slice/dither.hpp). Per row: the span of columns where some layer has a
/// live voxel, the layers' cells and properties there transposed into lanes (dither_lanes.cpp),
/// the grouped kernel (dither_group_kernel.cpp), the choices transposed back as pixels or
/// material indices, void around them; the error state of both halves cleared only where it was
/// written.
///
/// Cost: per row O(layers nx / 8) to find the live span, the transposes and the kernel over that
/// span (about 4 ns per grid voxel of the bench job, tools/bench/bench_dither.cpp) and O(nx) per
/// layer to write void outside it; memory 2 (nx + 2) 40 floats of error and 8 (np + 2) floats per
/// column.
#include <algorithm>
#include <cstring>
#include <string>

#include "dither_kernels.hpp"
#include "trivox/error.hpp"
#include "trivox/slice/dither.hpp"
#include "trivox/slice/material.hpp"

namespace trivox::slice {

using namespace detail;

bool LayerGroupDitherer::serves(DitherMode mode, const MaterialMapper& mapper) noexcept {
  return group_kernel_available() && mode == DitherMode::fs && mapper.colour_only() && mapper.materials() >= 5 &&
         mapper.materials() <= 8 && mapper.colour_materials() == std::array<int, 5>{0, 1, 2, 3, 4};
}

LayerGroupDitherer::LayerGroupDitherer(int nx, const MaterialMapper& mapper, double pitch_x, double pitch_y)
    : nx_(nx), np_(mapper.properties()) {
  if (nx < 1) throw Error("dithering: " + std::to_string(nx) + " voxels per row; expected at least 1");
  if (!serves(DitherMode::fs, mapper))
    throw Error("dithering: the grouped kernel needs AVX2 and a colour-only mapper with the colour materials at 0..4 of "
                "at most 8",
                ErrorKind::failed);
  const auto cp = mapper.colour_properties();
  ir_ = cp[0], ig_ = cp[1], ib_ = cp[2];
  float w[8][4];
  mask_weights(pitch_x, pitch_y, w);
  for (int m = 0; m < 8; ++m)
    for (int j = 0; j < 4; ++j) std::fill(weights_[m][j], weights_[m][j] + 8, w[m][j]);
  const auto n = static_cast<std::size_t>(nx), np = static_cast<std::size_t>(np_);
  error_.assign(2 * (n + 2) * group_stride, 0.0f);
  props_.assign(n * np * 8, 0.0f);
  cell_.assign((n + 2) * 8, -1);
  chosen_.assign(n * 8, 0);
  no_props_.assign(n * np, 0.0f);
  no_cells_.assign(n, -1);
}

void LayerGroupDitherer::begin(int layers) {
  if (layers < 1 || layers > max_layers)
    throw Error("dithering: a group of " + std::to_string(layers) + " layers; expected 1 to " + std::to_string(max_layers),
                ErrorKind::failed);
  layers_ = layers;
  next_row_ = 0;
  clear_errors();
}

void LayerGroupDitherer::clear_errors() {
  std::fill(error_.begin(), error_.end(), 0.0f);
  for (auto& r : written_) r = {0, -1};
}

void LayerGroupDitherer::row_(int row, const std::int32_t* const* cell, const float* const* props, const std::int32_t (&table)[8],
                              std::int64_t* const* counts, int& lo, int& hi) {
  if (layers_ < 1) throw Error("dithering: a row before begin()", ErrorKind::failed);
  if (row < 0 || row < next_row_)
    throw Error("dithering: row " + std::to_string(row) + " after rows up to " + std::to_string(next_row_ - 1) +
                    "; expected increasing rows (error diffusion runs downwards)",
                ErrorKind::failed);
  if (row > next_row_) clear_errors();
  next_row_ = row + 1;
  // The columns where some layer has a live voxel, [lo, hi]: outside them the kernel would only
  // write void and pass no error (a void column drops what is aimed at it), so it visits these.
  lo = nx_, hi = -1;
  for (int l = 0; l < layers_; ++l) widen_live_span(cell[l], nx_, lo, hi);
  // The error for the next row: the kernel writes columns lo - 1 .. hi + 1 (pads included), and
  // the rest of that half must read as zero, as the whole-row kernel leaves it. Each half is
  // zero outside the columns it last had written (written_), so only those are cleared.
  const std::size_t half = error_.size() / 2;
  const int d = row % 2 == 0 ? 1 : 0;  // the half written now
  float* in = error_.data() + (d == 1 ? 0 : half);
  float* down = error_.data() + (d == 1 ? half : 0);
  auto clear = [&](int c0, int c1) {  // columns c0..c1 of down (-1 and nx: the pads)
    if (c0 <= c1)
      std::fill(down + static_cast<std::size_t>(c0 + 1) * group_stride, down + static_cast<std::size_t>(c1 + 2) * group_stride, 0.0f);
  };
  auto& [w0, w1] = written_[static_cast<std::size_t>(d)];
  if (hi < 0) {
    clear(w0, w1);
    w0 = 0, w1 = -1;
    return;
  }
  clear(w0, std::min(w1, lo - 2));
  clear(std::max(w0, hi + 2), w1);
  w0 = lo - 1, w1 = hi + 1;
  // The layers' live columns into lanes (lanes without a layer: void cells, zero properties),
  // with void cells on either side (the kernel reads the forward neighbour's).
  const auto n = static_cast<std::size_t>(hi - lo + 1), np = static_cast<std::size_t>(np_), ulo = static_cast<std::size_t>(lo);
  const void* cs[8];
  const void* ps[8];
  for (int l = 0; l < 8; ++l) {
    const bool used = l < layers_;
    cs[l] = used ? static_cast<const void*>(cell[l] + ulo) : no_cells_.data();
    ps[l] = used ? static_cast<const void*>(props[l] + ulo * np) : no_props_.data();
  }
  std::fill_n(cell_.data() + ulo * 8, 8, -1);             // column lo - 1
  std::fill_n(cell_.data() + (ulo + n + 1) * 8, 8, -1);   // column hi + 1
  to_lanes(cs, n, cell_.data() + (ulo + 1) * 8);
  to_lanes(ps, n * np, props_.data() + ulo * np * 8);
  float lane_counts[group_k][8] = {};
  group_row(nx_, lo, hi, row % 2 == 0, weights_, cell_.data(), props_.data(), np_, ir_, ig_, ib_, in, down, table, chosen_.data(),
            lane_counts);
  for (int l = 0; l < layers_; ++l)
    for (int k = 0; k < group_k; ++k) counts[l][k] += static_cast<std::int64_t>(lane_counts[k][l]);
}

void LayerGroupDitherer::dither_paint(int row, const std::int32_t* const* cell, const float* const* props,
                                      const std::array<std::uint32_t, 256>& colours, std::uint8_t* const* rgba,
                                      std::int64_t* const* counts) {
  const FlushDenormals flush;
  // The kernel writes table[choice] per lane (choice 7: void).
  std::int32_t table[8] = {};
  for (int k = 0; k < group_k; ++k) table[k] = static_cast<std::int32_t>(colours[static_cast<std::size_t>(k)]);
  table[7] = static_cast<std::int32_t>(colours[void_material]);
  int live_lo, live_hi;
  row_(row, cell, props, table, counts, live_lo, live_hi);
  const bool any = live_lo <= live_hi;
  const auto nx = static_cast<std::size_t>(nx_);
  const std::size_t lo = any ? static_cast<std::size_t>(live_lo) : nx, hi = any ? static_cast<std::size_t>(live_hi) : nx - 1;
  void* outs[8];
  for (int l = 0; l < layers_; ++l) {
    for (std::size_t j = 0; j < lo; ++j) std::memcpy(rgba[l] + 4 * j, &colours[void_material], 4);
    for (std::size_t j = hi + 1; j < nx; ++j) std::memcpy(rgba[l] + 4 * j, &colours[void_material], 4);
    outs[l] = rgba[l] + 4 * lo;
  }
  if (any) from_lanes(chosen_.data() + lo * 8, hi - lo + 1, layers_, outs);
}

void LayerGroupDitherer::dither(int row, const std::int32_t* const* cell, const float* const* props, std::uint8_t* const* index,
                                std::int64_t* const* counts) {
  const FlushDenormals flush;
  const std::int32_t table[8] = {0, 1, 2, 3, 4, 0, 0, void_material};
  int live_lo, live_hi;
  row_(row, cell, props, table, counts, live_lo, live_hi);
  const bool any = live_lo <= live_hi;
  const auto nx = static_cast<std::size_t>(nx_);
  const std::size_t lo = any ? static_cast<std::size_t>(live_lo) : nx, hi = any ? static_cast<std::size_t>(live_hi) : nx - 1;
  std::uint8_t* outs[8];
  for (int l = 0; l < layers_; ++l) {
    std::fill(index[l], index[l] + lo, void_material);
    std::fill(index[l] + hi + 1, index[l] + nx, void_material);
    outs[l] = index[l] + lo;
  }
  if (any) from_lanes_bytes(chosen_.data() + lo * 8, hi - lo + 1, layers_, outs);
}

}  // namespace trivox::slice
