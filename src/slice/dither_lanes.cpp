/// @file src/slice/dither_lanes.cpp
/// @brief The grouped ditherer's transposes (LayerGroupDitherer): up to eight layers' rows into
/// column-major lanes (one 8-wide vector per column, lane l = layer l) and the choices back into
/// rows, as 4-byte pixels or one-byte material indices, and the span of a row's live voxels.
/// AVX2 on x86-64; elsewhere the grouped ditherer does not run and these do nothing.
///
/// Cost: per 4 columns four 128-bit-half loads and a 4 x 4 transpose within the halves (no
/// cross-half permutes); per 8 columns of bytes two packs, two shuffles and the row stores; the
/// live span scans eight cells per compare from either end, outside the span found so far only.
#include <algorithm>
#include <cstdint>
#include <cstring>

#include "dither_kernels.hpp"

namespace trivox::slice::detail {

#ifdef TRIVOX_DITHER_AVX2

namespace {

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

}  // namespace

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

namespace {

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

}  // namespace

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

#else
void widen_live_span(const std::int32_t*, int, int&, int&) noexcept {}
void to_lanes(const void* const*, std::size_t, void*) noexcept {}
void from_lanes(const void*, std::size_t, int, void* const*) noexcept {}
void from_lanes_bytes(const void*, std::size_t, int, std::uint8_t* const*) noexcept {}
#endif  // TRIVOX_DITHER_AVX2

}  // namespace trivox::slice::detail
