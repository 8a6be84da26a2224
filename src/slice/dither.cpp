/// @file src/slice/dither.cpp
/// @brief The dithering modes and their names, the error-diffusion weights of a voxel's aspect
/// ratio (per neighbour mask, renormalised), and LayerDitherer: one layer's rows through the fs
/// (Floyd & Steinberg 1976), stochastic or none kernel, the fs error carried from band to band,
/// and dither_paint's fused colour pass.
///
/// The kernels live beside this file: dither_fs.cpp and dither_fs_avx2.cpp (error diffusion),
/// dither_stochastic.cpp; the grouped ditherer in dither_group.cpp. Cost: the kernels' per voxel
/// (trivox/slice/dither.hpp), for `none` O(materials) per voxel here; O(nx s) per layer (and per
/// skipped band) to clear the fs error state, O(s) per row for its pads; 2 (nx + 2) s floats of
/// error, s the error stride.
#include "trivox/slice/dither.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "dither_kernels.hpp"
#include "trivox/error.hpp"
#include "trivox/slice/material.hpp"

namespace trivox::slice {

using namespace detail;

namespace detail {

/// The fs weights per neighbour-availability mask (forward, down_back, down, down_forward),
/// renormalised over the available neighbours.
void mask_weights(double pitch_x, double pitch_y, float (&out)[8][4]) {
  const DiffusionWeights w = diffusion_weights(pitch_x, pitch_y);
  for (int mask = 0; mask < 8; ++mask) {
    const double f = mask & has_forward ? w.forward : 0.0;
    const double b = mask & has_down_back ? w.down_back : 0.0;
    const double d = mask & has_down_forward ? w.down_forward : 0.0;
    const double s = f + b + w.down + d;
    out[mask][0] = static_cast<float>(f / s);
    out[mask][1] = static_cast<float>(b / s);
    out[mask][2] = static_cast<float>(w.down / s);
    out[mask][3] = static_cast<float>(d / s);
  }
}

}  // namespace detail

DitherMode parse_dither_mode(std::string_view text) {
  if (text == "fs") return DitherMode::fs;
  if (text == "stochastic") return DitherMode::stochastic;
  if (text == "none") return DitherMode::none;
  std::string shown(text.substr(0, 40));
  for (char& c : shown)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
  throw Error("--dither " + shown + ": expected fs, stochastic or none");
}

std::string_view dither_mode_name(DitherMode mode) noexcept {
  switch (mode) {
    case DitherMode::fs: return "fs";
    case DitherMode::stochastic: return "stochastic";
    case DitherMode::none: return "none";
  }
  return "fs";
}

DiffusionWeights diffusion_weights(double pitch_x, double pitch_y) {
  if (!(std::isfinite(pitch_x) && std::isfinite(pitch_y) && pitch_x > 0 && pitch_y > 0))
    throw Error("dithering: voxel pitches " + std::to_string(pitch_x) + " x " + std::to_string(pitch_y) +
                "; expected finite positive numbers");
  // Floyd-Steinberg on a square grid, each weight scaled by (square distance) / (distance
  // here); only the aspect ratio matters, so the square grid's pitch is taken as 1 and the
  // voxel as 1 x a.
  const double a = pitch_y / pitch_x;
  const double diagonal = std::sqrt(2.0) / std::sqrt(1.0 + a * a);
  const double forward = 7.0, down_back = 3.0 * diagonal, down = 5.0 / a, down_forward = 1.0 * diagonal;
  const double sum = forward + down_back + down + down_forward;
  return {forward / sum, down_back / sum, down / sum, down_forward / sum};
}

LayerDitherer::LayerDitherer(DitherMode mode, int nx, int materials, double pitch_x, double pitch_y,
                             std::uint64_t seed)
    : mode_(mode), nx_(nx), materials_(materials), seed_(seed) {
  if (nx < 1) throw Error("dithering: " + std::to_string(nx) + " voxels per row; expected at least 1");
  if (materials < 1 || materials > max_palette_materials)
    throw Error("dithering: " + std::to_string(materials) + " materials; expected 1 to 254");
  mask_weights(pitch_x, pitch_y, weights_);
  if (mode_ == DitherMode::fs) {
    const auto stride = static_cast<std::size_t>(error_stride(materials));
    error_.assign(2 * (static_cast<std::size_t>(nx) + 2) * stride, 0.0f);
    scratch_.assign(2 * stride, 0.0f);
  }
}

void LayerDitherer::begin_layer(int layer) {
  layer_ = layer;
  next_row_ = 0;
  std::fill(error_.begin(), error_.end(), 0.0f);
}

void LayerDitherer::dither(int row0, int rows, const std::int32_t* cell, const float* fractions, std::uint8_t* out) {
  const FlushDenormals flush;
  if (rows <= 0) return;
  if (row0 < 0)
    throw Error("dithering layer " + std::to_string(layer_) + ": row " + std::to_string(row0) +
                    "; expected rows from 0", ErrorKind::failed);
  const auto nx = static_cast<std::size_t>(nx_), m = static_cast<std::size_t>(materials_);
  if (mode_ == DitherMode::fs) {
    if (row0 < next_row_)
      throw Error("dithering layer " + std::to_string(layer_) + ": rows from " + std::to_string(row0) +
                      " after rows up to " + std::to_string(next_row_ - 1) +
                      "; expected increasing rows (error diffusion runs downwards)",
                  ErrorKind::failed);
    // Skipped rows are void rows: they pass no error on.
    if (row0 > next_row_) std::fill(error_.begin(), error_.end(), 0.0f);
    next_row_ = row0 + rows;
  }
  for (int r = 0; r < rows; ++r) {
    const std::size_t at = static_cast<std::size_t>(r) * nx;
    switch (mode_) {
      case DitherMode::fs: fs_row(row0 + r, cell + at, fractions + at * m, out + at); break;
      case DitherMode::stochastic: stochastic_row(row0 + r, cell + at, fractions + at * m, out + at); break;
      case DitherMode::none: none_row(cell + at, fractions + at * m, out + at); break;
    }
  }
}

void LayerDitherer::fs_row(int row, const std::int32_t* cell, const float* fractions, std::uint8_t* out) {
  const std::size_t half = error_.size() / 2;
  // The halves swap roles every row: row r reads half r % 2 and writes the other.
  float* in = error_.data() + (row % 2 == 0 ? 0 : half);
  float* down = error_.data() + (row % 2 == 0 ? half : 0);
  const int stride = error_stride(materials_);
  const FsRow a{nx_, materials_, stride, row % 2 == 0, weights_, cell, fractions, out, in, down, scratch_.data()};
  fs_kernel_for(materials_)(a);
  // `in` was zeroed as it was read, but for its pads: they collected 0 * error when this half
  // was the row below. Keep them exactly zero.
  std::fill(in, in + stride, 0.0f);
  std::fill(in + half - static_cast<std::size_t>(stride), in + half, 0.0f);
}

void LayerDitherer::dither_paint(int row, const std::int32_t* cell, const float* props, const MaterialMapper& mapper,
                                 const std::array<std::uint32_t, 256>& colours, std::uint8_t* rgba, std::int64_t* counts) {
  const FlushDenormals flush;
  if (mapper.materials() != materials_)
    throw Error("dithering: a mapper of " + std::to_string(mapper.materials()) + " materials for a ditherer of " +
                    std::to_string(materials_) + "; expected the same palette",
                ErrorKind::failed);
  const auto nx = static_cast<std::size_t>(nx_);
  const auto cm = mapper.colour_materials();
  const bool fused = mode_ == DitherMode::fs && mapper.colour_only() && materials_ >= 5 && materials_ <= 8 &&
                     cm == std::array<int, 5>{0, 1, 2, 3, 4};
  if (!fused) {
    row_fractions_.resize(nx * static_cast<std::size_t>(materials_));
    row_chosen_.resize(nx);
    mapper.fractions(props, cell, nx, row_fractions_.data());
    dither(row, 1, cell, row_fractions_.data(), row_chosen_.data());
    for (std::size_t v = 0; v < nx; ++v) {
      const std::uint8_t m = row_chosen_[v];
      std::memcpy(rgba + 4 * v, &colours[m], 4);
      if (m != void_material) ++counts[m];
    }
    return;
  }
  if (row < 0 || row < next_row_)
    throw Error("dithering layer " + std::to_string(layer_) + ": row " + std::to_string(row) + " after rows up to " +
                    std::to_string(next_row_ - 1) + "; expected increasing rows (error diffusion runs downwards)",
                ErrorKind::failed);
  if (row > next_row_) std::fill(error_.begin(), error_.end(), 0.0f);
  next_row_ = row + 1;
  const std::size_t half = error_.size() / 2;
  float* in = error_.data() + (row % 2 == 0 ? 0 : half);
  float* down = error_.data() + (row % 2 == 0 ? half : 0);
  const int stride = error_stride(materials_);
  const FsRow a{nx_, materials_, stride, row % 2 == 0, weights_, cell, nullptr, nullptr, in, down, scratch_.data()};
  const auto cp = mapper.colour_properties();
  const ColourIO io{props, mapper.properties(), cp[0], cp[1], cp[2], colours.data(), rgba};
  V4 c[2] = {V4{}, V4{}};
  colour_kernel_for(materials_)(a, io, c);
  std::fill(in, in + stride, 0.0f);  // as fs_row
  std::fill(in + half - static_cast<std::size_t>(stride), in + half, 0.0f);
  for (int m = 0; m < materials_; ++m) counts[m] += static_cast<std::int64_t>(c[m / 4][m % 4]);
}

void LayerDitherer::stochastic_row(int row, const std::int32_t* cell, const float* fractions,
                                   std::uint8_t* out) const {
  const std::uint64_t key =
      mix64(mix64(mix64(seed_) ^ static_cast<std::uint32_t>(layer_)) ^ static_cast<std::uint32_t>(row));
  stochastic_kernel_for(materials_)(nx_, materials_, key, cell, fractions, out);
}

void LayerDitherer::none_row(const std::int32_t* cell, const float* fractions, std::uint8_t* out) const {
  const int m = materials_;
  for (int x = 0; x < nx_; ++x) {
    if (cell[x] < 0) {
      out[x] = void_material;
      continue;
    }
    const float* f = fractions + static_cast<std::ptrdiff_t>(x) * m;
    int best = 0;
    for (int k = 1; k < m; ++k)
      if (f[k] > f[best]) best = k;
    out[x] = static_cast<std::uint8_t>(best);
  }
}

}  // namespace trivox::slice
