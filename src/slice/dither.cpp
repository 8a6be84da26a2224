#include "trivox/slice/dither.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "trivox/error.hpp"
#include "trivox/slice/material.hpp"

namespace trivox::slice {

namespace {

/// splitmix64's step and finaliser (Steele, Lea & Flood 2014): a bijective 64-bit mix with full
/// avalanche, so that neighbouring voxels' keys give unrelated numbers.
inline std::uint64_t mix64(std::uint64_t z) noexcept {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

/// Neighbour-availability mask bits (the down neighbour always counts: the next row's voids
/// are not known yet when a row is processed).
constexpr int has_forward = 1, has_down_back = 2, has_down_forward = 4;

/// Error-buffer floats per voxel: the material count rounded up to a multiple of 4 for the
/// small palettes, so that the diffusion loops run as whole SSE vectors (the padding stays 0).
constexpr int error_stride(int materials) { return materials <= 8 ? (materials + 3) / 4 * 4 : materials; }

/// What one fs row needs; the kernel is a template on the material count so that the small
/// counts of real palettes get fully unrolled, vectorised loops (0: any count).
struct FsRow {
  int nx, materials, stride;
  bool left_to_right;
  const float (*weights)[4];
  const std::int32_t* cell;
  const float* fractions;
  std::uint8_t* out;
  float* in;       // incoming error of this row: (nx + 2) * stride, one pad voxel each side
  float* down;     // error for the next row, same layout: overwritten by the kernels for up to
                   // 8 materials; accumulated into (zero on entry) by the runtime-count kernel,
                   // which zeroes `in` as it reads it so that the halves can swap
  float* scratch;  // 2 * stride, for the runtime-count kernel
};

/// Four floats as one SSE/NEON register (GCC and Clang vector extensions: portable, no
/// intrinsics). Unaligned loads and stores go through memcpy.
using V4 = float __attribute__((vector_size(16)));
inline V4 load(const float* p) noexcept {
  V4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store(float* p, V4 v) noexcept { std::memcpy(p, &v, sizeof v); }

/// The MC fractions of a voxel as ceil(MC / 4) vectors, zero-padded, without reading past
/// them (the last voxel's are the end of the caller's buffer) and without a trip through the
/// stack (a vector load of a partially stored slot stalls store forwarding).
template <int MC>
inline void load_fractions(const float* p, V4* f) noexcept {
  for (int i = 0; i < MC / 4; ++i) f[i] = load(p + 4 * i);
  constexpr int r = MC % 4, q = MC / 4;
  if constexpr (r == 1) f[q] = V4{p[4 * q], 0.0f, 0.0f, 0.0f};
  if constexpr (r == 2) f[q] = V4{p[4 * q], p[4 * q + 1], 0.0f, 0.0f};
  if constexpr (r == 3) f[q] = V4{p[4 * q], p[4 * q + 1], p[4 * q + 2], 0.0f};
}

/// fs for palettes of up to 8 materials, NV = ceil(MC / 4) vectors per voxel. The choice is a
/// serial dependency from voxel to voxel (through the in-row error), so the kernel keeps it
/// short and branch-free: masked max, first lane equal to it, one-hot by comparison.
template <int MC>
void fs_kernel(const FsRow& a) {
  constexpr int NV = (MC + 3) / 4, S = 4 * NV;
  V4 lane[NV], carry[NV];
  for (int i = 0; i < NV; ++i) {
    lane[i] = V4{0.0f, 1.0f, 2.0f, 3.0f} + static_cast<float>(4 * i);
    carry[i] = V4{};
  }
  const V4 none = V4{} - 3.0e38f, far = V4{} + 1.0e9f, one = V4{} + 1.0f;

  // Locals, not a's fields: stores through the uint8_t output may alias anything, and the
  // compiler would reload every field after each.
  const std::int32_t* const cell = a.cell;
  const float* const fractions = a.fractions;
  std::uint8_t* const out = a.out;
  const float(*const weights)[4] = a.weights;
  const int nx = a.nx, dir = a.left_to_right ? 1 : -1;
  int x = a.left_to_right ? 0 : nx - 1;
  const float* in = a.in + S;  // skip the pad: in + x * S is voxel x
  float* down = a.down + S;
  // The next row's error at x - dir, x and x + dir is complete once voxel x + dir... is done:
  // down[x - dir] receives from x - 2 dir, x - dir and x, in that order. So it is summed in
  // registers (here: down[x], fwd: down[x + dir]) and stored once, final, in the same order of
  // additions as accumulating in memory would use; every voxel and both pads get stored, so
  // `down` needs no clearing and `in` is only read.
  V4 acc_here[NV], acc_fwd[NV];
  for (int i = 0; i < NV; ++i) acc_here[i] = acc_fwd[i] = V4{};
  for (int t = 0; t < nx; ++t, x += dir) {
    const float* e = in + static_cast<std::ptrdiff_t>(x) * S;
    float* d_back = down + static_cast<std::ptrdiff_t>(x - dir) * S;
    if (cell[x] < 0) {  // void: the error aimed here is dropped, none leaves
      out[x] = void_material;
      for (int i = 0; i < NV; ++i) {
        store(d_back + 4 * i, acc_here[i]);
        acc_here[i] = acc_fwd[i];
        acc_fwd[i] = V4{};
        carry[i] = V4{};
      }
      continue;
    }
    V4 f[NV];
    load_fractions<MC>(fractions + static_cast<std::ptrdiff_t>(x) * MC, f);
    // Corrected fractions v = (f + e) + carry. The candidates are the materials this voxel
    // holds (error from a neighbouring region must not print a material absent here; it stays
    // in the error): `masked` pushes the others to -3e38. Everything not involving carry is
    // off the voxel-to-voxel dependency chain, which runs carry -> masked -> max -> one-hot ->
    // error -> carry.
    V4 v[NV], masked[NV];
    for (int i = 0; i < NV; ++i) {
      const V4 base = f[i] + load(e + 4 * i);
      const V4 penalised = base + (f[i] > 0.0f ? V4{} : none);
      v[i] = base + carry[i];
      masked[i] = penalised + carry[i];
    }
    V4 mv = masked[0];
    for (int i = 1; i < NV; ++i) mv = mv > masked[i] ? mv : masked[i];
    const float top = std::max(std::max(mv[0], mv[1]), std::max(mv[2], mv[3]));
    V4 hit[NV], hits = V4{}, index = V4{};
    for (int i = 0; i < NV; ++i) {
      hit[i] = masked[i] == top ? one : V4{};
      hits += hit[i];
      index += hit[i] * lane[i];
    }
    float best = index[0] + index[1] + index[2] + index[3];
    if (hits[0] + hits[1] + hits[2] + hits[3] != 1.0f) [[unlikely]] {
      // A tie (exact equality of corrected fractions): the lowest index wins.
      V4 first = far;
      for (int i = 0; i < NV; ++i) {
        const V4 c = hit[i] > 0.0f ? lane[i] : far;
        first = first < c ? first : c;
      }
      best = std::min(std::min(first[0], first[1]), std::min(first[2], first[3]));
      for (int i = 0; i < NV; ++i) hit[i] = lane[i] == best ? one : V4{};
    }
    out[x] = static_cast<std::uint8_t>(best);

    const bool last = t + 1 == nx;
    const int mask = (!last && cell[x + dir] >= 0 ? has_forward : 0) | (t > 0 ? has_down_back : 0) |
                     (!last ? has_down_forward : 0);
    const float* w = weights[mask];
    // Unavailable neighbours have weight 0, and the pads absorb the edge writes.
    for (int i = 0; i < NV; ++i) {
      const V4 err = v[i] - hit[i];
      carry[i] = w[0] * err;
      store(d_back + 4 * i, acc_here[i] + w[1] * err);
      acc_here[i] = acc_fwd[i] + w[2] * err;
      acc_fwd[i] = w[3] * err;
    }
  }
  // x is one past the last voxel: flush down[x - dir] (the last voxel) and down[x] (a pad).
  for (int i = 0; i < NV; ++i) {
    store(down + static_cast<std::ptrdiff_t>(x - dir) * S + 4 * i, acc_here[i]);
    store(down + static_cast<std::ptrdiff_t>(x) * S + 4 * i, acc_fwd[i]);
  }
}

/// fs for any number of materials (more than 8): the same choice and diffusion, one float at
/// a time.
template <>
void fs_kernel<0>(const FsRow& a) {
  const int m = a.materials, s = a.stride;
  float* carry = a.scratch;
  float* v = a.scratch + s;
  std::fill(carry, carry + s, 0.0f);

  const int nx = a.nx, dir = a.left_to_right ? 1 : -1;
  int x = a.left_to_right ? 0 : nx - 1;
  float* in = a.in + s;
  float* down = a.down + s;
  for (int t = 0; t < nx; ++t, x += dir) {
    float* e = in + static_cast<std::ptrdiff_t>(x) * s;
    if (a.cell[x] < 0) {
      a.out[x] = void_material;
      for (int k = 0; k < s; ++k) e[k] = 0.0f, carry[k] = 0.0f;
      continue;
    }
    const float* f = a.fractions + static_cast<std::ptrdiff_t>(x) * m;
    int best = 0;
    float best_v = -3.0e38f;
    for (int k = 0; k < m; ++k) {
      v[k] = f[k] + e[k] + carry[k];
      e[k] = 0.0f;
      if (f[k] > 0.0f && v[k] > best_v) best = k, best_v = v[k];
    }
    a.out[x] = static_cast<std::uint8_t>(best);
    v[best] -= 1.0f;

    const bool last = t + 1 == nx;
    const int mask = (!last && a.cell[x + dir] >= 0 ? has_forward : 0) | (t > 0 ? has_down_back : 0) |
                     (!last ? has_down_forward : 0);
    const float* w = a.weights[mask];
    float* d_back = down + static_cast<std::ptrdiff_t>(x - dir) * s;
    float* d_here = down + static_cast<std::ptrdiff_t>(x) * s;
    float* d_fwd = down + static_cast<std::ptrdiff_t>(x + dir) * s;
    for (int k = 0; k < m; ++k) {
      const float ek = v[k];
      carry[k] = w[0] * ek;
      d_back[k] += w[1] * ek;
      d_here[k] += w[2] * ek;
      d_fwd[k] += w[3] * ek;
    }
  }
}

using FsKernel = void (*)(const FsRow&);

FsKernel fs_kernel_for(int materials) {
  switch (materials) {
    case 1: return fs_kernel<1>;
    case 2: return fs_kernel<2>;
    case 3: return fs_kernel<3>;
    case 4: return fs_kernel<4>;
    case 5: return fs_kernel<5>;
    case 6: return fs_kernel<6>;
    case 7: return fs_kernel<7>;
    case 8: return fs_kernel<8>;
    default: return fs_kernel<0>;
  }
}

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

using StochasticKernel = void (*)(int, int, std::uint64_t, const std::int32_t*, const float*, std::uint8_t*);

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

}  // namespace

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
  const DiffusionWeights w = diffusion_weights(pitch_x, pitch_y);
  for (int mask = 0; mask < 8; ++mask) {
    const double f = mask & has_forward ? w.forward : 0.0;
    const double b = mask & has_down_back ? w.down_back : 0.0;
    const double d = mask & has_down_forward ? w.down_forward : 0.0;
    const double s = f + b + w.down + d;
    weights_[mask][0] = static_cast<float>(f / s);
    weights_[mask][1] = static_cast<float>(b / s);
    weights_[mask][2] = static_cast<float>(w.down / s);
    weights_[mask][3] = static_cast<float>(d / s);
  }
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
