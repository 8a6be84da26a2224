/// @file src/slice/dither_fs_avx2.cpp
/// @brief The colour path's error diffusion in one 8-lane AVX2 vector per voxel (x86-64 only,
/// chosen at run time by colour_kernel_for in dither_fs.cpp): fs_kernel of dither_fs.cpp for
/// 5 to 8 materials with the fractions computed from each voxel's colour and the choices painted
/// as RGBA pixels, bit for bit the same output as the 4-lane kernel.
///
/// Cost: per voxel one vector operation where the 4-lane kernel needs two, and a single
/// vmovmskps for the choice (5.8 instead of 6.9 ns per voxel of the bench job, fs_kernel8's
/// comment); the dependency chain from voxel to voxel is select -> add -> max -> compare, as in
/// the 4-lane kernel. No allocation.
#include <cstring>

#include "dither_kernels.hpp"
#include "trivox/slice/material.hpp"

#ifdef TRIVOX_DITHER_AVX2

namespace trivox::slice::detail {

namespace {

/// Eight floats as one AVX register (x86-64 kernels compiled for AVX2, chosen at run time).
using V8 = float __attribute__((vector_size(32)));
using I8 = std::int32_t __attribute__((vector_size(32)));
[[gnu::target("avx2"), gnu::always_inline]] inline V8 load8(const float* p) noexcept {
  V8 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
[[gnu::target("avx2"), gnu::always_inline]] inline void store8(float* p, V8 v) noexcept { std::memcpy(p, &v, sizeof v); }
[[gnu::target("avx2"), gnu::always_inline]] inline V8 select8(I8 m, V8 b, V8 a) noexcept {
  I8 ib, ia;
  std::memcpy(&ib, &b, sizeof ib);
  std::memcpy(&ia, &a, sizeof ia);
  const I8 r = (m & ib) | (~m & ia);
  V8 out;
  std::memcpy(&out, &r, sizeof out);
  return out;
}
/// The eight lanes' sign bits (lane 0 lowest): one vmovmskps.
[[gnu::target("avx2"), gnu::always_inline]] inline unsigned sign_bits8(I8 m) noexcept {
  return static_cast<unsigned>(__builtin_ia32_movmskps256(reinterpret_cast<V8>(m)));
}

/// fs_kernel for the colour path with 5 to 8 materials in one 8-lane vector per voxel (the
/// error rows' stride is 8 floats for these palettes): the same IEEE operations lane by lane
/// and the same choice (the largest masked value, the lowest lane among ties) as fs_kernel,
/// hence bit-identical output, with half the vector instructions and a single vmovmskps for
/// the choice: 5.8 instead of 6.9 ns per voxel of the bench job (tools/bench/bench_slice.cpp).
template <int MC>
[[gnu::always_inline, gnu::target("avx2")]] inline void fs_kernel8(const FsRow& a, const ColourIO io, V4* counts) {
  static_assert(MC >= 5 && MC <= 8);
  constexpr int S = 8;
  const V8 none = V8{} - 3.0e38f, one = V8{} + 1.0f;
  const std::int32_t* const cell = a.cell;
  V8 wv[8][4];
  for (int m = 0; m < 8; ++m)
    for (int k = 0; k < 4; ++k) wv[m][k] = V8{} + a.weights[m][k];
  const int nx = a.nx, dir = a.left_to_right ? 1 : -1;
  int x = a.left_to_right ? 0 : nx - 1;
  const float* in = a.in + S;
  float* down = a.down + S;
  const float* props = io.props;
  const int np = io.np, ir = io.ir, ig = io.ig, ib = io.ib;
  const std::uint32_t* colours = io.colours;
  std::uint8_t* rgba = io.rgba;
  V8 acc_here{}, acc_fwd{}, cnt{}, ca{}, cb{};
  I8 hm{};
  for (int t = 0; t < nx; ++t, x += dir) {
    const float* e = in + static_cast<std::ptrdiff_t>(x) * S;
    float* d_back = down + static_cast<std::ptrdiff_t>(x - dir) * S;
    if (cell[x] < 0) {
      std::memcpy(rgba + 4 * static_cast<std::ptrdiff_t>(x), &colours[void_material], 4);
      store8(d_back, acc_here);
      acc_here = acc_fwd;
      acc_fwd = V8{};
      ca = cb = V8{};
      continue;
    }
    const float* p = props + static_cast<std::ptrdiff_t>(x) * np;
    float c[5];
    cmykw_fractions(p[ir], p[ig], p[ib], c);
    const V8 f{c[0], c[1], c[2], c[3], c[4], 0.0f, 0.0f, 0.0f};
    const V8 base = f + load8(e);
    const V8 penalised = base + (f > 0.0f ? V8{} : none);
    const V8 carry = select8(hm, cb, ca);
    const V8 v = base + carry;
    const V8 masked = penalised + carry;
    V8 mv = masked;
    mv = mv > __builtin_shufflevector(mv, mv, 4, 5, 6, 7, 0, 1, 2, 3) ? mv : __builtin_shufflevector(mv, mv, 4, 5, 6, 7, 0, 1, 2, 3);
    mv = mv > __builtin_shufflevector(mv, mv, 2, 3, 0, 1, 6, 7, 4, 5) ? mv : __builtin_shufflevector(mv, mv, 2, 3, 0, 1, 6, 7, 4, 5);
    mv = mv > __builtin_shufflevector(mv, mv, 1, 0, 3, 2, 5, 4, 7, 6) ? mv : __builtin_shufflevector(mv, mv, 1, 0, 3, 2, 5, 4, 7, 6);
    hm = masked == mv;
    const unsigned bits = sign_bits8(hm);
    const int best = __builtin_ctz(bits);
    if (bits & (bits - 1)) [[unlikely]]
      hm = I8{0, 1, 2, 3, 4, 5, 6, 7} == best;
    std::memcpy(rgba + 4 * static_cast<std::ptrdiff_t>(x), &colours[best], 4);
    const bool last = t + 1 == nx;
    const int mask = (!last && cell[x + dir] >= 0 ? has_forward : 0) | (t > 0 ? has_down_back : 0) |
                     (!last ? has_down_forward : 0);
    const V8* w = wv[mask];
    const V8 hit = select8(hm, one, V8{});
    cnt += hit;
    const V8 err = v - hit;
    ca = w[0] * v;
    cb = w[0] * (v - one);
    store8(d_back, acc_here + w[1] * err);
    acc_here = acc_fwd + w[2] * err;
    acc_fwd = w[3] * err;
  }
  store8(down + static_cast<std::ptrdiff_t>(x - dir) * S, acc_here);
  store8(down + static_cast<std::ptrdiff_t>(x) * S, acc_fwd);
  counts[0] += V4{cnt[0], cnt[1], cnt[2], cnt[3]};
  counts[1] += V4{cnt[4], cnt[5], cnt[6], cnt[7]};
}

}  // namespace

template <int MC>
[[gnu::target("avx2")]] void colour_kernel_avx2(const FsRow& a, const ColourIO& io, V4* counts) {
  fs_kernel8<MC>(a, io, counts);
}

template void colour_kernel_avx2<5>(const FsRow&, const ColourIO&, V4*);
template void colour_kernel_avx2<6>(const FsRow&, const ColourIO&, V4*);
template void colour_kernel_avx2<7>(const FsRow&, const ColourIO&, V4*);
template void colour_kernel_avx2<8>(const FsRow&, const ColourIO&, V4*);

}  // namespace trivox::slice::detail

#endif  // TRIVOX_DITHER_AVX2
