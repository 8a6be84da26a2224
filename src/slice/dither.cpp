#include "trivox/slice/dither.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>

#include "trivox/error.hpp"
#include "trivox/slice/material.hpp"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#endif

namespace trivox::slice {

namespace {

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

/// Where the fs kernel's fractions come from and where its choices go: the plain form reads
/// fraction vectors and writes material indices.
struct FractionsIO {
  static constexpr bool counts = false;
  const float* fractions;
  std::uint8_t* out;
  template <int MC>
  void load(int x, V4* f) const noexcept {
    load_fractions<MC>(fractions + static_cast<std::ptrdiff_t>(x) * MC, f);
  }
  void put(int x, int best) const noexcept { out[x] = static_cast<std::uint8_t>(best); }
  void put_void(int x) const noexcept { out[x] = void_material; }
};

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
  void put_void(int x) const noexcept { std::memset(rgba + 4 * static_cast<std::ptrdiff_t>(x), 0, 4); }
};

using I4 = std::int32_t __attribute__((vector_size(16)));
/// Lane-wise m ? b : a, for a mask m of comparison results (all ones or all zeros per lane).
inline V4 select(I4 m, V4 b, V4 a) noexcept {
  I4 ib, ia;
  std::memcpy(&ib, &b, sizeof ib);
  std::memcpy(&ia, &a, sizeof ia);
  const I4 r = (m & ib) | (~m & ia);
  V4 out;
  std::memcpy(&out, &r, sizeof out);
  return out;
}

/// The four lanes' sign bits (lane 0 lowest): of a comparison mask, which lanes are set.
inline unsigned sign_bits(I4 m) noexcept {
#if defined(__SSE__)
  return static_cast<unsigned>(__builtin_ia32_movmskps(reinterpret_cast<V4>(m)));
#else
  return static_cast<unsigned>((m[0] & 1) | (m[1] & 2) | (m[2] & 4) | (m[3] & 8));
#endif
}

/// fs for palettes of up to 8 materials, NV = ceil(MC / 4) vectors per voxel. The choice is a
/// serial dependency from voxel to voxel (through the in-row error), and the loop body is long
/// enough that its instruction count matters as much, so the kernel keeps both short:
/// - the carry to the next voxel, w0 (v - onehot(k)), is computed for both outcomes of every
///   lane before the choice (w0 v and w0 (v - 1)), so that the choice only selects: the chain
///   is select -> add -> max -> compare;
/// - the choice is read from the comparison's sign bits (the lowest set bit is the lowest index
///   among ties), and the weights come pre-broadcast, one vector per neighbour and mask.
/// The floats are those of w0 (v - onehot(k)) computed after the choice, operation for operation
/// (the generic kernel's, which the tests compare against).
/// counts (IO::counts): per-lane counts of the choices, as exact floats (a row has far fewer
/// than 2^24 voxels).
template <int MC, class IO>
[[gnu::always_inline]] inline void fs_kernel(const FsRow& a, const IO io, V4* counts) {
  constexpr int NV = (MC + 3) / 4, S = 4 * NV;
  const V4 none = V4{} - 3.0e38f, one = V4{} + 1.0f;

  // Locals, not a's fields: stores through the uint8_t output may alias anything, and the
  // compiler would reload every field after each.
  const std::int32_t* const cell = a.cell;
  V4 wv[8][4];
  for (int m = 0; m < 8; ++m)
    for (int k = 0; k < 4; ++k) wv[m][k] = V4{} + a.weights[m][k];
  const int nx = a.nx, dir = a.left_to_right ? 1 : -1;
  int x = a.left_to_right ? 0 : nx - 1;
  const float* in = a.in + S;  // skip the pad: in + x * S is voxel x
  float* down = a.down + S;
  // The next row's error at x - dir, x and x + dir is complete once voxel x + dir... is done:
  // down[x - dir] receives from x - 2 dir, x - dir and x, in that order. So it is summed in
  // registers (here: down[x], fwd: down[x + dir]) and stored once, final, in the same order of
  // additions as accumulating in memory would use; every voxel and both pads get stored, so
  // `down` needs no clearing and `in` is only read.
  V4 acc_here[NV], acc_fwd[NV], cnt[NV];
  // The carry into the current voxel is hm ? cb : ca (lane-wise): w0 (v - 1) where the previous
  // voxel chose that lane, w0 v elsewhere; both 0 at a row start or after a void voxel.
  V4 ca[NV], cb[NV];
  I4 hm[NV];
  for (int i = 0; i < NV; ++i) acc_here[i] = acc_fwd[i] = cnt[i] = ca[i] = cb[i] = V4{}, hm[i] = I4{};
  for (int t = 0; t < nx; ++t, x += dir) {
    const float* e = in + static_cast<std::ptrdiff_t>(x) * S;
    float* d_back = down + static_cast<std::ptrdiff_t>(x - dir) * S;
    if (cell[x] < 0) {  // void: the error aimed here is dropped, none leaves
      io.put_void(x);
      for (int i = 0; i < NV; ++i) {
        store(d_back + 4 * i, acc_here[i]);
        acc_here[i] = acc_fwd[i];
        acc_fwd[i] = V4{};
        ca[i] = cb[i] = V4{};
      }
      continue;
    }
    V4 f[NV];
    io.template load<MC>(x, f);
    // Corrected fractions v = (f + e) + carry. The candidates are the materials this voxel
    // holds (error from a neighbouring region must not print a material absent here; it stays
    // in the error): `masked` pushes the others to -3e38.
    V4 v[NV], masked[NV];
    for (int i = 0; i < NV; ++i) {
      const V4 base = f[i] + load(e + 4 * i);
      const V4 penalised = base + (f[i] > 0.0f ? V4{} : none);
      const V4 carry = select(hm[i], cb[i], ca[i]);
      v[i] = base + carry;
      masked[i] = penalised + carry;
    }
    V4 mv = masked[0];
    for (int i = 1; i < NV; ++i) mv = mv > masked[i] ? mv : masked[i];
    // Horizontal max, broadcast to every lane.
    mv = mv > __builtin_shufflevector(mv, mv, 2, 3, 0, 1) ? mv : __builtin_shufflevector(mv, mv, 2, 3, 0, 1);
    mv = mv > __builtin_shufflevector(mv, mv, 1, 0, 3, 2) ? mv : __builtin_shufflevector(mv, mv, 1, 0, 3, 2);
    unsigned bits = 0;
    for (int i = 0; i < NV; ++i) {
      hm[i] = masked[i] == mv;
      bits |= sign_bits(hm[i]) << (4 * i);
    }
    // The lowest set bit: the lowest index among ties (exact equality of corrected fractions),
    // which then is the only one chosen.
    const int best = __builtin_ctz(bits);
    if (bits & (bits - 1)) [[unlikely]]
      for (int i = 0; i < NV; ++i) {
        const I4 lanes = I4{0, 1, 2, 3} + 4 * i;
        hm[i] = lanes == best;
      }
    io.put(x, best);

    const bool last = t + 1 == nx;
    const int mask = (!last && cell[x + dir] >= 0 ? has_forward : 0) | (t > 0 ? has_down_back : 0) |
                     (!last ? has_down_forward : 0);
    const V4* w = wv[mask];
    // Unavailable neighbours have weight 0, and the pads absorb the edge writes.
    for (int i = 0; i < NV; ++i) {
      const V4 hit = select(hm[i], one, V4{});
      if constexpr (IO::counts) cnt[i] += hit;
      const V4 err = v[i] - hit;
      ca[i] = w[0] * v[i];
      cb[i] = w[0] * (v[i] - one);
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
  if constexpr (IO::counts)
    for (int i = 0; i < NV; ++i) counts[i] += cnt[i];
}

#if defined(__x86_64__) && defined(__GNUC__)
#define TRIVOX_DITHER_AVX2 1
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
      std::memset(rgba + 4 * static_cast<std::ptrdiff_t>(x), 0, 4);
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

#endif  // x86-64

/// The fused kernels: fs_kernel (4-lane vectors) for the baseline and, picked at run time on
/// x86-64 CPUs with AVX2, fs_kernel8 (one 8-lane vector per voxel). Both run the same IEEE
/// operations lane by lane (no contraction: the project compiles with -ffp-contract=off) and
/// choose alike, so their output is bit-identical; the tests run whichever the machine picks
/// against the step-by-step path. (Interleaving two layers' rows in one loop, so that their
/// dependency chains overlap, measured no faster: the loop is bound by its instruction count.)
using ColourKernel = void (*)(const FsRow&, const ColourIO&, V4*);
template <int MC>
void colour_kernel(const FsRow& a, const ColourIO& io, V4* counts) {
  fs_kernel<MC>(a, io, counts);
}
#ifdef TRIVOX_DITHER_AVX2
template <int MC>
[[gnu::target("avx2")]] void colour_kernel_avx2(const FsRow& a, const ColourIO& io, V4* counts) {
  fs_kernel8<MC>(a, io, counts);
}
#endif

ColourKernel colour_kernel_for(int materials) {
#ifdef TRIVOX_DITHER_AVX2
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (avx2) switch (materials) {
      case 5: return colour_kernel_avx2<5>;
      case 6: return colour_kernel_avx2<6>;
      case 7: return colour_kernel_avx2<7>;
      default: return colour_kernel_avx2<8>;
    }
#endif
  switch (materials) {
    case 5: return colour_kernel<5>;
    case 6: return colour_kernel<6>;
    case 7: return colour_kernel<7>;
    default: return colour_kernel<8>;
  }
}

template <int MC>
void fs_kernel(const FsRow& a) {
  fs_kernel<MC>(a, FractionsIO{a.fractions, a.out}, nullptr);
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

// ------------------------------------------------------------------------------------------
// Grouped layers (LayerGroupDitherer): one lane per layer, AVX2

/// Colour materials carried per voxel by the grouped kernel, and floats of error per column.
constexpr int group_k = 5, group_stride = group_k * 8;

#ifdef TRIVOX_DITHER_AVX2

/// What one grouped row needs (LayerGroupDitherer::dither_paint). Column-major buffers hold,
/// per column, one 8-float (or int32) vector whose lane l belongs to the group's layer l.
struct GroupRow {
  int nx;
  int lo, hi;                  // the columns to visit (every lane void outside them; lo <= hi)
  bool left_to_right;
  const __m256 (*weights)[4];  // per neighbour-availability mask, broadcast
  const std::int32_t* cell;    // (nx + 2) * 8: column c at (c + 1) * 8; the pads are void
  const float* props;          // nx * np * 8: property p of column c at (c np + p) * 8
  int np, ir, ig, ib;
  const float* in;             // (nx + 2) * group_stride: incoming error, one pad column each side
  float* down;                 // the same for the next row (every column and both pads stored)
  __m256i colours;             // per choice the value written (lanes 0..4; lane 7 void): RGBA, or the index
  std::int32_t* rgba;          // nx * 8: the chosen colour of column c at c * 8
  __m256* counts;              // group_k vectors: per material, per lane, added to
};

/// 4 x 4 transposes within each 128-bit half: in each half, rows r0..r3 (4 floats each) into
/// columns.
[[gnu::target("avx2"), gnu::always_inline]] inline void transpose4_halves(__m256& r0, __m256& r1, __m256& r2,
                                                                          __m256& r3) noexcept {
  const __m256 t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpackhi_ps(r0, r1);
  const __m256 t2 = _mm256_unpacklo_ps(r2, r3), t3 = _mm256_unpackhi_ps(r2, r3);
  r0 = _mm256_shuffle_ps(t0, t2, 0x44), r1 = _mm256_shuffle_ps(t0, t2, 0xee);
  r2 = _mm256_shuffle_ps(t1, t3, 0x44), r3 = _mm256_shuffle_ps(t1, t3, 0xee);
}

/// Elements j..j+3 of row a in the low half and of row b in the high half (the 128-bit insert
/// from memory is a load, not the cross-half permute an 8 x 8 transpose otherwise needs: several
/// micro-ops on AMD's Zen 1, a 3-cycle operation on Intel's one shuffle port).
[[gnu::target("avx2"), gnu::always_inline]] inline __m256 halves(const float* a, const float* b) noexcept {
  return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(a)), _mm_loadu_ps(b), 1);
}

/// dst[j * 8 + l] = src[l][j] for j < n (4-byte elements): eight rows into column-major lanes.
/// Per 4 columns: rows l and l + 4 paired in halves, then 4 x 4 transposes within the halves.
[[gnu::target("avx2")]] void to_lanes(const void* const* src, std::size_t n, void* dst) noexcept {
  const float* s[8];
  for (int l = 0; l < 8; ++l) s[l] = static_cast<const float*>(src[l]);
  float* d = static_cast<float*>(dst);
  std::size_t j = 0;
  for (; j + 4 <= n; j += 4) {
    // Columns j..j+3: lane l of column c comes from row l (low half l < 4, high half l - 4).
    __m256 r0 = halves(s[0] + j, s[4] + j), r1 = halves(s[1] + j, s[5] + j), r2 = halves(s[2] + j, s[6] + j),
           r3 = halves(s[3] + j, s[7] + j);
    transpose4_halves(r0, r1, r2, r3);
    float* o = d + j * 8;
    _mm256_storeu_ps(o, r0), _mm256_storeu_ps(o + 8, r1), _mm256_storeu_ps(o + 16, r2), _mm256_storeu_ps(o + 24, r3);
  }
  for (; j < n; ++j)  // as bytes: the elements may be int32 (cells)
    for (int l = 0; l < 8; ++l) std::memcpy(d + j * 8 + static_cast<std::size_t>(l), s[l] + j, 4);
}

/// dst[l][j] = src[j * 8 + l] for j < n and l < lanes: the inverse of to_lanes (per 4 columns,
/// 4 x 4 transposes within the halves, then each half stored to its row).
[[gnu::target("avx2")]] void from_lanes(const void* src, std::size_t n, int lanes, void* const* dst) noexcept {
  const float* s = static_cast<const float*>(src);
  float* d[8];
  for (int l = 0; l < 8; ++l) d[l] = static_cast<float*>(dst[l]);
  std::size_t j = 0;
  for (; j + 4 <= n; j += 4) {
    const float* q = s + j * 8;
    __m256 r[4];
    for (int c = 0; c < 4; ++c) r[c] = _mm256_loadu_ps(q + 8 * c);
    transpose4_halves(r[0], r[1], r[2], r[3]);  // r[l]: row l's 4 columns low, row l + 4's high
    for (int l = 0; l < 4 && l < lanes; ++l) _mm_storeu_ps(d[l] + j, _mm256_castps256_ps128(r[l]));
    for (int l = 4; l < lanes; ++l) _mm_storeu_ps(d[l] + j, _mm256_extractf128_ps(r[l - 4], 1));
  }
  for (; j < n; ++j)
    for (int l = 0; l < lanes; ++l) std::memcpy(d[l] + j, s + j * 8 + static_cast<std::size_t>(l), 4);
}

/// The low bytes of 4 columns of lanes (q: 4 x 8 int32), per half transposed: bytes 4 l .. 4 l + 3
/// of the low half are lane l's 4 columns, those of the high half lane l + 4's.
[[gnu::target("avx2"), gnu::always_inline]] inline __m256i low_bytes4(const std::int32_t* q) noexcept {
  const __m256i low = _mm256_set1_epi32(0xff);
  // Within a half: bytes 4 c + l (column c, lane l) to 4 l + c.
  const __m256i turn = _mm256_setr_epi8(0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15, 0, 4, 8, 12, 1, 5, 9, 13, 2, 6,
                                        10, 14, 3, 7, 11, 15);
  __m256i c[4];
  for (int i = 0; i < 4; ++i) c[i] = _mm256_and_si256(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(q + 8 * i)), low);
  // Per half: columns 0..3, 4 bytes each (the values fit: no saturation), then turned.
  const __m256i p = _mm256_packus_epi16(_mm256_packus_epi32(c[0], c[1]), _mm256_packus_epi32(c[2], c[3]));
  return _mm256_shuffle_epi8(p, turn);
}

/// dst[l][j] = the low byte of src[j * 8 + l] (int32) for j < n and l < lanes: from_lanes into
/// bytes (material indices). Per 8 columns: the low bytes packed (within halves) into one
/// vector per 4 columns, 4 x 4 bytes transposed by one shuffle, and the two vectors' rows
/// interleaved into 8-byte rows.
[[gnu::target("avx2")]] void from_lanes_bytes(const void* src, std::size_t n, int lanes, std::uint8_t* const* dst) noexcept {
  const auto* s = static_cast<const std::int32_t*>(src);
  std::size_t j = 0;
  for (; j + 8 <= n; j += 8) {
    const __m256i a = low_bytes4(s + j * 8), b = low_bytes4(s + j * 8 + 32);
    // Per half, 8-byte rows: lo holds lanes 0, 1 (high half: 4, 5), hi lanes 2, 3 (6, 7).
    const __m256i lo = _mm256_unpacklo_epi32(a, b), hi = _mm256_unpackhi_epi32(a, b);
    const __m128i rows[4] = {_mm256_castsi256_si128(lo), _mm256_castsi256_si128(hi), _mm256_extracti128_si256(lo, 1),
                             _mm256_extracti128_si256(hi, 1)};
    for (int l = 0; l < lanes; ++l) {
      const __m128i r = rows[(l / 4) * 2 + (l % 4) / 2];
      if (l % 2 == 0) _mm_storel_epi64(reinterpret_cast<__m128i*>(dst[l] + j), r);
      else _mm_storeh_pd(reinterpret_cast<double*>(dst[l] + j), _mm_castsi128_pd(r));
    }
  }
  for (; j < n; ++j)
    for (int l = 0; l < lanes; ++l) dst[l][j] = static_cast<std::uint8_t>(s[j * 8 + static_cast<std::size_t>(l)]);
}

/// Widens [lo, hi] to hold every i < n with c[i] >= 0 (a layer's live voxels in its row), looking
/// only outside [lo, hi] (lo > hi: empty so far): from the left up to lo, from the right down to
/// hi, eight cells per compare.
[[gnu::target("avx2")]] void widen_live_span(const std::int32_t* c, int n, int& lo, int& hi) noexcept {
  const __m256i minus1 = _mm256_set1_epi32(-1);
  const int left_end = std::min(lo, n);  // scan [0, left_end)
  int i = 0;
  for (; i + 8 <= left_end; i += 8) {
    const int m = _mm256_movemask_ps(
        _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(c + i)), minus1)));
    if (m != 0) break;
  }
  for (; i < left_end; ++i)
    if (c[i] >= 0) {
      lo = i;
      break;
    }
  if (lo > hi) hi = lo < n ? lo : -1;  // the first live one found (or none at all so far)
  if (hi < 0) {
    lo = n;  // no live voxel left of n: the whole row is void so far
    return;
  }
  int j = n;  // scan (hi, n) from the right
  for (; j - 8 > hi; j -= 8) {
    const int m = _mm256_movemask_ps(
        _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(c + j - 8)), minus1)));
    if (m != 0) break;
  }
  for (--j; j > hi; --j)
    if (c[j] >= 0) {
      hi = j;
      break;
    }
}

/// What the two group kernels share: the row's pointers and weights, the state carried along the
/// row (per material the error for the next voxel and the two accumulating in the next row), and
/// the steps that do not depend on how the lanes' masks are held.
struct GroupLoop {
  static constexpr int K = group_k, S = group_stride;
  const GroupRow& a;
  int nx, dir, x;
  const float* in;
  float* down;
  const std::int32_t* cell;
  std::ptrdiff_t np8;
  const float *pr, *pg, *pb;
  // The weights of the first, middle and last columns (the forward neighbour's per lane).
  const __m256 *first_with, *first_without, *mid_with, *mid_without, *last_without;
  __m256 acc_here[K], acc_fwd[K], carry[K];
  // The counts: per material and lane, the hits so far.
  __m256i cnt[K];
  const __m256 none = _mm256_set1_ps(-3.0e38f), one = _mm256_set1_ps(1.0f), zero = _mm256_setzero_ps();
  const __m256i seven = _mm256_set1_epi32(7), minus1 = _mm256_set1_epi32(-1);
  const __m256i void_px = _mm256_permutevar8x32_epi32(a.colours, seven);  // the table's void entry in every lane

  // The visit: columns lo..hi (or hi..lo), step t of the row's nx (t = 0 its first column,
  // nx - 1 its last: the weights at the row's ends depend on t).
  int t_begin, t_end;

  [[gnu::target("avx2"), gnu::always_inline]] explicit GroupLoop(const GroupRow& row)
      : a(row), nx(row.nx), dir(row.left_to_right ? 1 : -1), x(row.left_to_right ? row.lo : row.hi), in(row.in + S),
        down(row.down + S), cell(row.cell + 8), np8(8 * static_cast<std::ptrdiff_t>(row.np)), pr(row.props + 8 * row.ir),
        pg(row.props + 8 * row.ig), pb(row.props + 8 * row.ib),
        first_with(row.weights[row.nx > 1 ? has_forward | has_down_forward : 0]),
        first_without(row.weights[row.nx > 1 ? has_down_forward : 0]),
        mid_with(row.weights[has_forward | has_down_back | has_down_forward]),
        mid_without(row.weights[has_down_back | has_down_forward]), last_without(row.weights[row.nx > 1 ? has_down_back : 0]),
        t_begin(row.left_to_right ? row.lo : row.nx - 1 - row.hi), t_end(t_begin + row.hi - row.lo + 1) {
    for (int k = 0; k < K; ++k) {
      acc_here[k] = acc_fwd[k] = carry[k] = _mm256_setzero_ps();
      cnt[k] = _mm256_setzero_si256();
    }
  }
  /// Column xs's incoming errors, and where its down-back neighbour's go.
  [[gnu::target("avx2"), gnu::always_inline]] const float* errors_in(std::ptrdiff_t xs, float*& d_back) const {
    d_back = down + (xs - dir) * S;
    return in + xs * S;
  }
  /// The layers' cell indices at column xs (lane l: layer l; -1 void).
  [[gnu::target("avx2"), gnu::always_inline]] __m256i cells(std::ptrdiff_t xs) const {
    return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(cell + xs * 8));
  }
  /// Column t's weights with and without its forward neighbour.
  [[gnu::target("avx2"), gnu::always_inline]] void weights(int t, const __m256*& with, const __m256*& without) const {
    const bool last = t + 1 == nx;
    with = t == 0 ? first_with : last ? last_without : mid_with;
    without = t == 0 ? first_without : last ? last_without : mid_without;
  }
  /// Every layer void at column xs: the error aimed here is dropped, none leaves.
  [[gnu::target("avx2"), gnu::always_inline]] void void_column(std::ptrdiff_t xs, float* d_back) {
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(a.rgba + xs * 8), void_px);
    for (int k = 0; k < K; ++k) {
      _mm256_storeu_ps(d_back + 8 * k, acc_here[k]);
      acc_here[k] = acc_fwd[k];
      acc_fwd[k] = carry[k] = _mm256_setzero_ps();
    }
  }
  /// cmykw_fractions of column xs, lane by lane: clamp (max(r, 0) is r > 0 ? r : 0, NaN -> 0;
  /// then min).
  [[gnu::target("avx2"), gnu::always_inline]] void fractions(std::ptrdiff_t xs, __m256 (&f)[K]) const {
    const std::ptrdiff_t at = xs * np8;
    const __m256 r = _mm256_min_ps(_mm256_max_ps(_mm256_loadu_ps(pr + at), zero), one);
    const __m256 g = _mm256_min_ps(_mm256_max_ps(_mm256_loadu_ps(pg + at), zero), one);
    const __m256 b = _mm256_min_ps(_mm256_max_ps(_mm256_loadu_ps(pb + at), zero), one);
    const __m256 m = _mm256_max_ps(r, _mm256_max_ps(g, b));
    const __m256 wh = _mm256_sub_ps(_mm256_add_ps(_mm256_add_ps(r, g), b), _mm256_add_ps(m, m));
    const __m256 s = _mm256_div_ps(one, _mm256_sub_ps(one, _mm256_min_ps(wh, zero)));
    f[0] = _mm256_mul_ps(_mm256_sub_ps(m, r), s);
    f[1] = _mm256_mul_ps(_mm256_sub_ps(m, g), s);
    f[2] = _mm256_mul_ps(_mm256_sub_ps(m, b), s);
    f[3] = _mm256_mul_ps(_mm256_sub_ps(one, m), s);
    f[4] = _mm256_max_ps(wh, zero);
  }
  /// Material k's error err at the column whose down-back neighbour is d_back, spread with the
  /// column's weights w (forward, down-back, down, down-forward).
  [[gnu::target("avx2"), gnu::always_inline]] void diffuse(int k, const __m256* w, __m256 err, float* d_back) {
    carry[k] = _mm256_mul_ps(w[0], err);
    _mm256_storeu_ps(d_back + 8 * k, _mm256_add_ps(acc_here[k], _mm256_mul_ps(w[1], err)));
    acc_here[k] = _mm256_add_ps(acc_fwd[k], _mm256_mul_ps(w[2], err));
    acc_fwd[k] = _mm256_mul_ps(w[3], err);
  }
  /// Adds the 6-bit fields of packed (group_kernel's counts) to cnt and clears them.
  [[gnu::target("avx2"), gnu::always_inline]] void unpack_counts(__m256i& packed, int& n) {
    const __m256i field = _mm256_set1_epi32(63);
    for (int k = 0; k < K; ++k)
      cnt[k] = _mm256_add_epi32(cnt[k], _mm256_and_si256(_mm256_srli_epi32(packed, 6 * k), field));
    packed = _mm256_setzero_si256();
    n = 0;
  }
  /// After the row: its last two columns' errors for the next row, and the counts.
  [[gnu::target("avx2"), gnu::always_inline]] void finish() {
    for (int k = 0; k < K; ++k) {
      _mm256_storeu_ps(down + static_cast<std::ptrdiff_t>(x - dir) * S + 8 * k, acc_here[k]);
      _mm256_storeu_ps(down + static_cast<std::ptrdiff_t>(x) * S + 8 * k, acc_fwd[k]);
      a.counts[k] = _mm256_add_ps(a.counts[k], _mm256_cvtepi32_ps(cnt[k]));
    }
  }
};

/// fs_kernel8 with the layers in the lanes (LayerGroupDitherer's comment): per colour material k
/// one vector holds the eight layers' values, so that the choice is a vertical max and a
/// compare, and void lanes are masked instead of branched over. The floats are fs_kernel8's
/// for the same lane, and cmykw_fractions' for the fractions (max and min equal its compares on
/// the clamped, NaN-free values; the clamps keep its NaN -> 0); the carry w0 (v - hit) equals
/// fs_kernel8's select between w0 v and w0 (v - 1) (v - 0 is v). So each layer's choices equal
/// the single-layer kernel's. The only difference: a void lane's error is +0 where the
/// single-layer kernel skips it, which can turn a -0 into +0, and a zero's sign never reaches a
/// comparison or a nonzero sum. (Computing the carry for both outcomes before the choice, as
/// fs_kernel8 does to shorten its chain, measured no faster here: with eight layers per step the
/// loop is bound by its vector instructions, not by its chain.)
[[gnu::target("avx2"), gnu::always_inline]] inline void group_kernel(const GroupRow& a) {
  constexpr int K = group_k;
  GroupLoop g(a);
  const __m256 none = g.none, one = g.one, zero = g.zero;
  const __m256i seven = g.seven, minus1 = g.minus1;
  // The counts in one vector of 6-bit fields (material k's at bit 6 k of its lane), unpacked
  // into g.cnt before a field can overflow: with 16 vector registers, five count vectors
  // would spill (AVX2 only; AVX-512's kernel has 32).
  const __m256i count_step = _mm256_setr_epi32(1, 1 << 6, 1 << 12, 1 << 18, 1 << 24, 0, 0, 0);
  constexpr int packed_max = 63;
  __m256i packed = _mm256_setzero_si256();
  int in_packed = 0;
  for (int t = g.t_begin; t < g.t_end; ++t, g.x += g.dir) {
    const std::ptrdiff_t xs = g.x;
    float* d_back;
    const float* e = g.errors_in(xs, d_back);
    const __m256i live_i = _mm256_cmpgt_epi32(g.cells(xs), minus1);
    if (_mm256_testz_si256(live_i, live_i)) {
      g.void_column(xs, d_back);
      continue;
    }
    const __m256 live = _mm256_castsi256_ps(live_i);
    // The forward neighbour's availability differs per layer (its voids); the rest does not.
    const __m256 fwd = _mm256_castsi256_ps(_mm256_cmpgt_epi32(g.cells(xs + g.dir), minus1));
    const __m256 *w_with, *w_without;
    g.weights(t, w_with, w_without);
    // The weights read from memory where they are: kept in registers, they spilled (and most
    // columns have a forward neighbour in every lane, or in none).
    const int fwd_lanes = _mm256_movemask_ps(fwd);
    __m256 mixed[4];
    const __m256* w = fwd_lanes == 0xff ? w_with : fwd_lanes == 0 ? w_without : mixed;
    if (w == mixed)
      for (int j = 0; j < 4; ++j) mixed[j] = _mm256_blendv_ps(w_without[j], w_with[j], fwd);
    __m256 f[K];
    g.fractions(xs, f);

    // The candidates are the materials the voxel holds: masked = v where f > 0, else -3e38.
    // (fs_kernel8 adds -3e38 to the others instead; either way they are far below the largest
    // held value, which is the same float, and so are the choice and the ties.)
    __m256 v[K], masked[K];
    for (int k = 0; k < K; ++k) {
      v[k] = _mm256_add_ps(_mm256_add_ps(f[k], _mm256_loadu_ps(e + 8 * k)), g.carry[k]);
      masked[k] = _mm256_blendv_ps(none, v[k], _mm256_cmp_ps(f[k], zero, _CMP_GT_OQ));
    }
    __m256 mv = _mm256_max_ps(_mm256_max_ps(masked[0], masked[1]), _mm256_max_ps(masked[2], masked[3]));
    mv = _mm256_max_ps(mv, masked[4]);
    // The lowest material among equal maxima, in live lanes (void: 7): from the highest down,
    // each equal one replaces the choice (one of them equals the maximum, so K - 1 stands when
    // no lower one does); the hits are the lanes whose choice is k.
    // (Void lanes choose among their finite values too, and are set to 7 after: one blend
    // instead of a mask per material.)
    __m256i idx = _mm256_set1_epi32(K - 1);
    for (int k = K - 2; k >= 0; --k)
      idx = _mm256_blendv_epi8(idx, _mm256_set1_epi32(k), _mm256_castps_si256(_mm256_cmp_ps(masked[k], mv, _CMP_EQ_OQ)));
    idx = _mm256_blendv_epi8(seven, idx, live_i);
    __m256 hit[K];
    for (int k = 0; k < K; ++k) hit[k] = _mm256_castsi256_ps(_mm256_cmpeq_epi32(idx, _mm256_set1_epi32(k)));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(a.rgba + xs * 8), _mm256_permutevar8x32_epi32(a.colours, idx));
    packed = _mm256_add_epi32(packed, _mm256_permutevar8x32_epi32(count_step, idx));
    if (++in_packed == packed_max) g.unpack_counts(packed, in_packed);
    for (int k = 0; k < K; ++k) {
      const __m256 h = _mm256_and_ps(hit[k], one);
      g.diffuse(k, w, _mm256_and_ps(live, _mm256_sub_ps(v[k], h)), d_back);  // +0 in void lanes
    }
  }
  g.unpack_counts(packed, in_packed);
  g.finish();
}

using GroupKernel = void (*)(const GroupRow&);
[[gnu::target("avx2")]] void group_kernel_avx2(const GroupRow& a) { group_kernel(a); }
/// group_kernel with AVX-512VL's mask registers for the lanes' masks (live, forward neighbour,
/// held materials, hits) and 32 vector registers: the same IEEE operations lane by lane (a
/// masked subtract of 1 is the subtract of the 0 or 1 it replaces: v - 0 is v), so the same
/// output, with masked moves in place of the AVX2 blends.
[[gnu::target("avx2,avx512f,avx512vl")]] void group_kernel_avx512vl(const GroupRow& a) {
  constexpr int K = group_k;
  GroupLoop g(a);
  const __m256 none = g.none, one = g.one, zero = g.zero;
  const __m256i seven = g.seven, minus1 = g.minus1;
  for (int t = g.t_begin; t < g.t_end; ++t, g.x += g.dir) {
    const std::ptrdiff_t xs = g.x;
    float* d_back;
    const float* e = g.errors_in(xs, d_back);
    const __mmask8 live = _mm256_cmpgt_epi32_mask(g.cells(xs), minus1);
    if (live == 0) {
      g.void_column(xs, d_back);
      continue;
    }
    const __mmask8 fwd = _mm256_cmpgt_epi32_mask(g.cells(xs + g.dir), minus1);
    const __m256 *w_with, *w_without;
    g.weights(t, w_with, w_without);
    __m256 w[4];
    for (int j = 0; j < 4; ++j) w[j] = _mm256_mask_blend_ps(fwd, w_without[j], w_with[j]);
    __m256 f[K];
    g.fractions(xs, f);
    __m256 v[K], masked[K];
    for (int k = 0; k < K; ++k) {
      v[k] = _mm256_add_ps(_mm256_add_ps(f[k], _mm256_loadu_ps(e + 8 * k)), g.carry[k]);
      masked[k] = _mm256_mask_mov_ps(none, _mm256_cmp_ps_mask(f[k], zero, _CMP_GT_OQ), v[k]);
    }
    __m256 mv = _mm256_max_ps(_mm256_max_ps(masked[0], masked[1]), _mm256_max_ps(masked[2], masked[3]));
    mv = _mm256_max_ps(mv, masked[4]);
    // As group_kernel: the lowest equal maximum from the highest down, the hits from the choice.
    __m256i idx = _mm256_mask_mov_epi32(seven, live, _mm256_set1_epi32(K - 1));  // void: 7
    for (int k = K - 2; k >= 0; --k)
      idx = _mm256_mask_mov_epi32(idx, _mm256_mask_cmp_ps_mask(live, masked[k], mv, _CMP_EQ_OQ), _mm256_set1_epi32(k));
    __mmask8 hit[K];
    for (int k = 0; k < K; ++k) hit[k] = _mm256_cmpeq_epi32_mask(idx, _mm256_set1_epi32(k));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(a.rgba + xs * 8), _mm256_permutevar8x32_epi32(a.colours, idx));
    for (int k = 0; k < K; ++k) {
      g.cnt[k] = _mm256_mask_sub_epi32(g.cnt[k], hit[k], g.cnt[k], minus1);
      // v - 1 where hit, v - 0 = v elsewhere; +0 in void lanes.
      g.diffuse(k, w, _mm256_maskz_mov_ps(live, _mm256_mask_sub_ps(v[k], hit[k], v[k], one)), d_back);
    }
  }
  g.finish();
}
GroupKernel group_kernel_for() {
  static const bool avx512vl = __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512f");
  if (avx512vl && !std::getenv("TRIVOX_NO_AVX512")) return group_kernel_avx512vl;
  return group_kernel_avx2;
}

/// One grouped row: the kernel on the job's buffers (plain pointers, so that callers need no
/// AVX types), adding the choices of each material and lane to counts.
[[gnu::target("avx2")]] void group_row(int nx, int lo, int hi, bool left_to_right, const float (*weights)[4][8], const std::int32_t* cell,
                                       const float* props, int np, int ir, int ig, int ib, const float* in, float* down,
                                       const std::int32_t* table, std::int32_t* rgba, float (*counts)[8]) {
  __m256 c[group_k];
  for (auto& v : c) v = _mm256_setzero_ps();
  const GroupRow a{nx, lo, hi, left_to_right, reinterpret_cast<const __m256(*)[4]>(weights), cell, props, np, ir, ig, ib, in, down,
                   _mm256_loadu_si256(reinterpret_cast<const __m256i*>(table)), rgba, c};
  group_kernel_for()(a);
  for (int k = 0; k < group_k; ++k) _mm256_storeu_ps(counts[k], _mm256_add_ps(_mm256_loadu_ps(counts[k]), c[k]));
}

bool group_kernel_available() noexcept {
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2;
}

#else
bool group_kernel_available() noexcept { return false; }
void widen_live_span(const std::int32_t*, int, int&, int&) noexcept {}
void to_lanes(const void* const*, std::size_t, void*) noexcept {}
void from_lanes(const void*, std::size_t, int, void* const*) noexcept {}
void from_lanes_bytes(const void*, std::size_t, int, std::uint8_t* const*) noexcept {}
void group_row(int, int, int, bool, const float (*)[4][8], const std::int32_t*, const float*, int, int, int, int, const float*, float*,
               const std::int32_t*, std::int32_t*, float (*)[8]) {}
#endif  // TRIVOX_DITHER_AVX2

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

// ------------------------------------------------------------------------------------------
// LayerGroupDitherer

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
