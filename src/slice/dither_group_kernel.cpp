/// @file src/slice/dither_group_kernel.cpp
/// @brief The grouped ditherer's row kernel (LayerGroupDitherer): error diffusion of up to eight
/// layers at once, layer l in lane l of one 8-wide vector per colour material, so that the
/// material choice is a vertical max and compare and the voxel-to-voxel chain is shared by the
/// layers; each lane runs the single-layer colour kernel's IEEE operations (dither_fs_avx2.cpp)
/// and chooses alike, so every layer's output is bit-identical to dithering it alone. Two
/// variants of the same loop, chosen at run time: AVX2 blends, and AVX-512VL mask registers
/// (TRIVOX_NO_AVX512 in the environment keeps the AVX2 one). x86-64 only; elsewhere
/// group_kernel_available() is false.
///
/// Cost: about 140 vector instructions per column for all the layers together, on the columns
/// from the first to the last live voxel of the group's row; no allocation.
#include <cstdint>
#include <cstdlib>

#include "dither_kernels.hpp"

namespace trivox::slice::detail {

#ifdef TRIVOX_DITHER_AVX2

namespace {

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

}  // namespace

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
void group_row(int, int, int, bool, const float (*)[4][8], const std::int32_t*, const float*, int, int, int, int, const float*, float*,
               const std::int32_t*, std::int32_t*, float (*)[8]) {}
#endif  // TRIVOX_DITHER_AVX2

}  // namespace trivox::slice::detail
