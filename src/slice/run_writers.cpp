// The run writers (run_writers.hpp): four voxels' m properties at a time as one flat block of
// 4m values, stepped from block to block by one add per value (the quadratic by forward
// differences: two), converted to floats, which vectorises; the property count known at compile
// time for m up to 4, so a block lives in registers. Every build (baseline, AVX2) performs the
// same operations in the same order without contraction: the same floats. Cost: O(n m) per run.
#include "run_writers.hpp"

#include <cstring>
#include <type_traits>

#include "trivox/slice/locator.hpp"

namespace trivox::slice::detail {

namespace {

/// Four doubles and four floats as vectors (GCC and Clang vector extensions; the same IEEE
/// operations lane by lane on any target).
using V4d = double __attribute__((vector_size(32)));
using V4f = float __attribute__((vector_size(16)));

/// The blocks of a run (write_linear_body, write_quadratic_body): `blocks` blocks of w = 4 M
/// values from base, stepped by one add each per block (by step, and step by step2 when Q);
/// then the values after the last block, of the rest of the run (`rest` of them). The rounding
/// this accumulates over a run of a few hundred voxels is some 1e-14 of the values, far below
/// the floats written. With M known, the values are M vectors of four, kept in registers.
template <int M, bool Q>
[[gnu::always_inline]] inline void step_blocks(float* o, int blocks, int w, int rest, double* base, double* step,
                                               const double* step2) {
  if constexpr (M > 0) {
    V4d bv[M], sv[M], s2[M];
    std::memcpy(bv, base, sizeof bv);
    std::memcpy(sv, step, sizeof sv);
    if constexpr (Q) std::memcpy(s2, step2, sizeof s2);
    for (int b = 0; b < blocks; ++b, o += w)
      for (int i = 0; i < M; ++i) {
        const V4f f = __builtin_convertvector(bv[i], V4f);
        std::memcpy(o + 4 * i, &f, sizeof f);
        bv[i] += sv[i];
        if constexpr (Q) sv[i] += s2[i];
      }
    std::memcpy(base, bv, sizeof bv);
  } else {
    for (int b = 0; b < blocks; ++b, o += w)
      for (int k = 0; k < w; ++k) {
        o[k] = static_cast<float>(base[k]);
        base[k] += step[k];
        if constexpr (Q) step[k] += step2[k];
      }
  }
  for (int k = 0; k < rest; ++k) o[k] = static_cast<float>(base[k]);
}

/// out[j m + h] = va[h] + j slope[h] for j < n, h < m (a run of voxels' properties from a linear
/// model): four voxels' m values at a time, as one flat run of 4m floats (base, stepped by delta per block),
/// which vectorises. M: m known at compile time (-1: m).
template <int M>
[[gnu::always_inline]] inline void write_linear_body(float* out, int n, int m, const double* va, const double* slope) {
  const int um = M >= 0 ? M : m;
  if (n < 8) {  // short runs (curved cells, boundaries): no set-up
    for (int j = 0; j < n; ++j)
      for (int h = 0; h < um; ++h) out[j * um + h] = static_cast<float>(va[h] + j * slope[h]);
    return;
  }
  constexpr int W = 4 * (M >= 0 ? M : Expansion::max_props);
  double base[W > 0 ? W : 1], delta[W > 0 ? W : 1];
  const int w = 4 * um;
  for (int h = 0; h < um; ++h)
    for (int v = 0; v < 4; ++v) {
      base[v * um + h] = va[h] + v * slope[h];
      delta[v * um + h] = 4.0 * slope[h];
    }
  const int blocks = n / 4;
  step_blocks<M, false>(out, blocks, w, (n - 4 * blocks) * um, base, delta, nullptr);
}

template <int M>
void write_linear(float* out, int n, int m, const double* va, const double* slope) {
  write_linear_body<M>(out, n, m, va, slope);
}
#if defined(__x86_64__)
/// The same operations on AVX registers (no contraction: the same floats).
template <int M>
[[gnu::target("avx2")]] void write_linear_avx2(float* out, int n, int m, const double* va, const double* slope) {
  write_linear_body<M>(out, n, m, va, slope);
}
#endif

/// out[j m + h] = va[h] + j (slope[h] + j curv[h]) for j < n, h < m (a run of voxels' properties
/// from a quadratic): four voxels at a time as one flat run of 4m values, voxel 4 b + v being
/// g(b) = (va + v slope + v^2 curv) + b (4 slope + 8 v curv) + b^2 (16 curv), stepped from block
/// to block by forward differences (g(b + 1) - g(b) = 4 slope + 8 v curv + (2 b + 1) 16 curv).
/// M as write_linear_body's.
template <int M>
[[gnu::always_inline]] inline void write_quadratic_body(float* out, int n, int m, const double* va, const double* slope,
                                                        const double* curv) {
  const int um = M >= 0 ? M : m;
  constexpr int W = 4 * (M >= 0 ? M : Expansion::max_props);
  double base[W > 0 ? W : 1], step[W > 0 ? W : 1], step2[W > 0 ? W : 1];
  const int w = 4 * um;
  for (int h = 0; h < um; ++h)
    for (int v = 0; v < 4; ++v) {
      base[v * um + h] = va[h] + v * (slope[h] + v * curv[h]);
      step[v * um + h] = 4.0 * slope[h] + 8.0 * v * curv[h] + 16.0 * curv[h];
      step2[v * um + h] = 32.0 * curv[h];
    }
  const int blocks = n / 4;
  step_blocks<M, true>(out, blocks, w, (n - 4 * blocks) * um, base, step, step2);
}

template <int M>
void write_quadratic(float* out, int n, int m, const double* va, const double* slope, const double* curv) {
  write_quadratic_body<M>(out, n, m, va, slope, curv);
}
#if defined(__x86_64__)
template <int M>
[[gnu::target("avx2")]] void write_quadratic_avx2(float* out, int n, int m, const double* va, const double* slope,
                                                  const double* curv) {
  write_quadratic_body<M>(out, n, m, va, slope, curv);
}
#endif

/// Whether the CPU runs the AVX2 builds of the kernels.
bool cpu_has_avx2() {
#if defined(__x86_64__)
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2;
#else
  return false;
#endif
}

/// get(std::integral_constant<int, M>) for the property count m: M = m up to 4, else -1 (the
/// kernels' run-time count).
template <class Get>
auto by_props(int m, Get get) {
  switch (m) {
    case 1: return get(std::integral_constant<int, 1>{});
    case 2: return get(std::integral_constant<int, 2>{});
    case 3: return get(std::integral_constant<int, 3>{});
    case 4: return get(std::integral_constant<int, 4>{});
    default: return get(std::integral_constant<int, -1>{});
  }
}

}  // namespace

WriteLinear pick_write(int m) {
  return by_props(m, [](auto k) -> WriteLinear {
#if defined(__x86_64__)
    if (cpu_has_avx2()) return write_linear_avx2<decltype(k)::value>;
#endif
    return write_linear<decltype(k)::value>;
  });
}

WriteQuadratic pick_write_quadratic(int m) {
  return by_props(m, [](auto k) -> WriteQuadratic {
#if defined(__x86_64__)
    if (cpu_has_avx2()) return write_quadratic_avx2<decltype(k)::value>;
#endif
    return write_quadratic<decltype(k)::value>;
  });
}

}  // namespace trivox::slice::detail
