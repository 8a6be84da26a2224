/// @file src/slice/dither_kernels.hpp
/// @brief Private to the slice module: what the dithering files share. The row descriptions the
/// error-diffusion kernels take (FsRow, ColourIO), the kernels' selectors (per material count and
/// CPU), the stochastic kernel's selector and hash, the guard that flushes subnormal floats, the
/// neighbour masks and their weights, and the lane transposes and row kernel of the grouped
/// ditherer (LayerGroupDitherer). trivox/slice/dither.hpp describes the methods; each kernel's
/// file gives its cost.
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "trivox/slice/material.hpp"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
/// x86-64: kernels compiled for AVX2 (and AVX-512VL), chosen at run time.
#define TRIVOX_DITHER_AVX2 1
/// The attribute of the functions compiled for AVX2 that other files call: a declaration must
/// carry its definition's target, or GCC takes the two for different versions of the function.
#define TRIVOX_DITHER_TARGET_AVX2 [[gnu::target("avx2")]]
#else
#define TRIVOX_DITHER_TARGET_AVX2
#endif

namespace trivox::slice::detail {

/// Flush-to-zero and denormals-are-zero for the floats of one dithering call, restored after
/// it. The error carried for a material a region does not hold is never chosen away: it spreads
/// over ever more voxels and decays towards subnormal floats, each of which costs an x86 core a
/// microcode assist per operation (the error-diffusion kernel of a one-layer job ran 2.4 times
/// slower on them). Flushed, such errors are 0 instead of below 1.2e-38, which no choice can
/// notice; every path of the fs arithmetic runs under this guard, so they agree bit for bit.
class FlushDenormals {
public:
#if defined(__x86_64__) && defined(__GNUC__)
  FlushDenormals() noexcept : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | 0x8040u); }  // FTZ | DAZ
  ~FlushDenormals() { _mm_setcsr(saved_); }
  FlushDenormals(const FlushDenormals&) = delete;
  FlushDenormals& operator=(const FlushDenormals&) = delete;

private:
  unsigned saved_;
#endif
};

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
/// intrinsics).
using V4 = float __attribute__((vector_size(16)));

/// The print job's form for colour-only models (MaterialMapper::colour_only, the five colour
/// materials at indices 0..4): the fractions are computed from each voxel's r, g, b right here
/// (cmykw_fractions, the mapper's own floats) and the choices are painted as RGBA pixels, so
/// that mapping and painting run in the shadow of the kernel's dependency chain and no fraction
/// or index buffer makes a round trip through memory.
struct ColourIO {
  static constexpr bool counts = true;
  const float* props;
  int np, ir, ig, ib;
  const std::uint32_t* colours;  // 256 entries
  std::uint8_t* rgba;
  template <int MC>
  void load(int x, V4* f) const noexcept {
    static_assert(MC >= 5);
    const float* p = props + static_cast<std::ptrdiff_t>(x) * np;
    float c[5];
    cmykw_fractions(p[ir], p[ig], p[ib], c);
    f[0] = V4{c[0], c[1], c[2], c[3]};
    f[1] = V4{c[4], 0.0f, 0.0f, 0.0f};
  }
  void put(int x, int best) const noexcept { std::memcpy(rgba + 4 * static_cast<std::ptrdiff_t>(x), &colours[best], 4); }
  void put_void(int x) const noexcept { std::memcpy(rgba + 4 * static_cast<std::ptrdiff_t>(x), &colours[void_material], 4); }
};

/// The fs weights per neighbour-availability mask (forward, down_back, down, down_forward),
/// renormalised over the available neighbours (dither.cpp).
void mask_weights(double pitch_x, double pitch_y, float (&out)[8][4]);

// ---- error diffusion, one layer at a time (dither_fs.cpp, dither_fs_avx2.cpp) ----

/// The fs row kernel for a palette of `materials` (dither_fs.cpp): unrolled 4-lane vectors up to
/// 8 materials, one float at a time beyond.
using FsKernel = void (*)(const FsRow&);
FsKernel fs_kernel_for(int materials);

/// The fused colour-path kernel for 5 to 8 materials (dither_fs.cpp picks it): 4-lane vectors,
/// or on x86-64 CPUs with AVX2 one 8-lane vector per voxel (dither_fs_avx2.cpp).
using ColourKernel = void (*)(const FsRow&, const ColourIO&, V4*);
ColourKernel colour_kernel_for(int materials);
#ifdef TRIVOX_DITHER_AVX2
/// The 8-lane colour kernel (dither_fs_avx2.cpp), instantiated for MC = 5..8.
template <int MC>
[[gnu::target("avx2")]] void colour_kernel_avx2(const FsRow& a, const ColourIO& io, V4* counts);
#endif

// ---- stochastic dithering (dither_stochastic.cpp) ----

/// The stochastic row kernel for a palette of `materials`: per voxel x of the row, the material
/// drawn by inverse CDF from mix64(key ^ x).
using StochasticKernel = void (*)(int, int, std::uint64_t, const std::int32_t*, const float*, std::uint8_t*);
StochasticKernel stochastic_kernel_for(int materials);

// ---- grouped layers, one lane per layer (dither_lanes.cpp, dither_group_kernel.cpp) ----

/// Colour materials carried per voxel by the grouped kernel, and floats of error per column.
constexpr int group_k = 5, group_stride = group_k * 8;

/// Whether this CPU runs the grouped kernel (x86-64 with AVX2).
bool group_kernel_available() noexcept;

/// dst[j * 8 + l] = src[l][j] for j < n (4-byte elements): eight rows into column-major lanes.
TRIVOX_DITHER_TARGET_AVX2 void to_lanes(const void* const* src, std::size_t n, void* dst) noexcept;
/// dst[l][j] = src[j * 8 + l] for j < n and l < lanes: the inverse of to_lanes.
TRIVOX_DITHER_TARGET_AVX2 void from_lanes(const void* src, std::size_t n, int lanes, void* const* dst) noexcept;
/// dst[l][j] = the low byte of src[j * 8 + l] (int32) for j < n and l < lanes: from_lanes into
/// bytes (material indices).
TRIVOX_DITHER_TARGET_AVX2 void from_lanes_bytes(const void* src, std::size_t n, int lanes,
                                                std::uint8_t* const* dst) noexcept;
/// Widens [lo, hi] to hold every i < n with c[i] >= 0 (a layer's live voxels in its row).
TRIVOX_DITHER_TARGET_AVX2 void widen_live_span(const std::int32_t* c, int n, int& lo, int& hi) noexcept;

/// One grouped row (dither_group_kernel.cpp): the columns lo..hi of a row of up to 8 layers in
/// lanes, dithered and painted table[choice] per column and lane into rgba, the choices of each
/// material and lane added to counts.
/// @param weights  per neighbour mask, the 4 weights broadcast to 8 lanes
/// @param cell     (nx + 2) * 8 cell ids, column c at (c + 1) * 8; the pads void
/// @param props    nx * np * 8 floats: property p of column c at (c np + p) * 8
/// @param ir, ig, ib  the colour properties' indices
/// @param in, down the row's incoming error and the next row's, (nx + 2) * group_stride each
/// @param table    8 values: per choice 0..4 the value written, [7] for void
/// @param rgba     nx * 8 values written (column c at c * 8)
/// @param counts   group_k x 8 floats added to
TRIVOX_DITHER_TARGET_AVX2 void group_row(int nx, int lo, int hi, bool left_to_right, const float (*weights)[4][8],
                                         const std::int32_t* cell, const float* props, int np, int ir, int ig, int ib,
                                         const float* in, float* down, const std::int32_t* table, std::int32_t* rgba,
                                         float (*counts)[8]);

}  // namespace trivox::slice::detail
