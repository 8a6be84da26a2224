/// @file src/slice/dither_fs.cpp
/// @brief Vector error diffusion (Floyd & Steinberg 1976, generalised to a simplex of
/// materials; docs/materials.md) along one row of one layer: the row kernels of LayerDitherer's
/// `fs` mode and of dither_paint's fused colour pass, and their selection by material count and
/// CPU.
///
/// Up to 8 materials the kernel runs on 4-lane vectors (ceil(materials / 4) per voxel), a
/// template on the material count, so that the choice, the carry to the next voxel and the
/// diffusion to the next row are unrolled vector operations; beyond 8, one float at a time. The
/// colour path's 8-lane AVX2 kernel is in dither_fs_avx2.cpp.
///
/// Cost: about 8 flops per material and voxel, O(1) per void voxel; the serial dependency from
/// voxel to voxel (the choice feeds the next voxel's carry) bounds the speed, together with the
/// loop's instruction count. No allocation.
#include <algorithm>
#include <cstring>

#include "dither_kernels.hpp"
#include "trivox/slice/material.hpp"

namespace trivox::slice::detail {

namespace {

/// Unaligned loads and stores of V4 go through memcpy.
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

template <int MC>
void colour_kernel(const FsRow& a, const ColourIO& io, V4* counts) {
  fs_kernel<MC>(a, io, counts);
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

}  // namespace

/// The fused kernels: fs_kernel (4-lane vectors) for the baseline and, picked at run time on
/// x86-64 CPUs with AVX2, fs_kernel8 (one 8-lane vector per voxel, dither_fs_avx2.cpp). Both run the same IEEE
/// operations lane by lane (no contraction: the project compiles with -ffp-contract=off) and
/// choose alike, so their output is bit-identical; the tests run whichever the machine picks
/// against the step-by-step path. (Interleaving two layers' rows in one loop, so that their
/// dependency chains overlap, measured no faster: the loop is bound by its instruction count.)
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

}  // namespace trivox::slice::detail
