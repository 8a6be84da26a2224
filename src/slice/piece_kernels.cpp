// The Bernstein kernels of a Bezier piece (piece_kernels.hpp): a net contracted with the
// Bernstein bases of its three directions, one direction after the other, O(o^3 H) for the
// value and its three first partials together (o the order, H the coordinates). Instantiated
// for the orders of the common pieces and the coordinate counts up to 10 (the sampler's
// expansions), with AVX2 and AVX-512 builds of the vector kernels chosen at run time: every
// build performs the same operations in the same order (no contraction), so all give the same
// floats.
#include "piece_kernels.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <type_traits>
#include <utility>

namespace trivox::slice::detail {

namespace {

// ---------------------------------------------------------------------------------------------
// Bernstein evaluation. A piece's geometry is kept as a net of H = 3 (polynomial) or 4 (rational,
// homogeneous wx wy wz w) coordinates per control point, u fastest; its properties as a separate
// net of m coordinates (pre-multiplied by the weight when rational), so Newton never touches them.

/// Bernstein polynomials of order n (degree n-1) at s and, when dB is not null, their derivatives.
/// T: double, or a vector of doubles (V8d below: several parameters at once, lane by lane the
/// same operations).
template <int O, class T = double>
inline void bernstein(int order, T s, T* B, std::type_identity_t<T>* dB) {
  const int n = O ? O : order;
  const T one = T{} + 1.0;
  if (n == 1) {
    B[0] = one;
    if (dB) dB[0] = T{};
    return;
  }
  const T s1 = one - s;
  T b[O ? O : max_order];  // degree n-2 values
  b[0] = one;
  for (int k = 1; k < n - 1; ++k) {
    b[k] = s * b[k - 1];
    for (int j = k - 1; j >= 1; --j) b[j] = s1 * b[j] + s * b[j - 1];
    b[0] *= s1;
  }
  if (dB) {
    const double deg = n - 1;
    dB[0] = -deg * b[0];
    for (int j = 1; j < n - 1; ++j) dB[j] = deg * (b[j - 1] - b[j]);
    dB[n - 1] = deg * b[n - 2];
  }
  B[n - 1] = s * b[n - 2];
  for (int j = n - 2; j >= 1; --j) B[j] = s1 * b[j] + s * b[j - 1];
  B[0] = s1 * b[0];
}

/// Geometry kernel: the first H coordinates of every control point (points `nc` coordinates
/// apart) contracted with the Bernstein basis: f = the value (H numbers) and, when D, the partials
/// in the piece's local parameters (3 x H more). Contracts u, then v, then w, so the partials cost
/// O(o^3 H) together. OU, OV, OW: the orders known at compile time (0: read from ord); the same
/// operations in the same order either way, so every instantiation gives the same floats.
template <int OU, int OV, int OW, int H, bool D, int NS = 0>
void geom_kernel(const double* net, int stride, const std::array<int, 3>& ord, const double* s, double* f) {
  constexpr int MU = OU ? OU : max_order, MV = OV ? OV : max_order, MW = OW ? OW : max_order;
  const int nc = NS ? NS : stride;  // coordinates per control point (compile-time when NS > 0)
  const int ou = OU ? OU : ord[0], ov = OV ? OV : ord[1], ow = OW ? OW : ord[2];
  double Bu[MU], Bv[MV], Bw[MW], dBu[D ? MU : 1], dBv[D ? MV : 1], dBw[D ? MW : 1];
  bernstein<OU>(ou, s[0], Bu, D ? dBu : nullptr);
  bernstein<OV>(ov, s[1], Bv, D ? dBv : nullptr);
  bernstein<OW>(ow, s[2], Bw, D ? dBw : nullptr);
  double S[H] = {}, Su[H] = {}, Sv[H] = {}, Sw[H] = {};
  for (int c = 0; c < ow; ++c) {
    double T[H] = {}, Tu[H] = {}, Tv[H] = {};
    for (int b = 0; b < ov; ++b) {
      const double* row = net + static_cast<std::ptrdiff_t>((c * ov + b) * ou) * nc;
      double r[H] = {}, ru[H] = {};
      for (int a = 0; a < ou; ++a)
        for (int h = 0; h < H; ++h) {
          r[h] += Bu[a] * row[a * nc + h];
          if constexpr (D) ru[h] += dBu[a] * row[a * nc + h];
        }
      for (int h = 0; h < H; ++h) {
        T[h] += Bv[b] * r[h];
        if constexpr (D) {
          Tu[h] += Bv[b] * ru[h];
          Tv[h] += dBv[b] * r[h];
        }
      }
    }
    for (int h = 0; h < H; ++h) {
      S[h] += Bw[c] * T[h];
      if constexpr (D) {
        Su[h] += Bw[c] * Tu[h];
        Sv[h] += Bw[c] * Tv[h];
        Sw[h] += dBw[c] * T[h];
      }
    }
  }
  for (int h = 0; h < H; ++h) {
    f[h] = S[h];
    if constexpr (D) {
      f[H + h] = Su[h];
      f[2 * H + h] = Sv[h];
      f[3 * H + h] = Sw[h];
    }
  }
}

/// Value kernel: all nc coordinates of the net at s (geometry and properties in one pass),
/// contracted u, then v, then w, so the sums form short independent chains (instruction-level
/// parallelism) rather than one chain of order^3 terms per coordinate.
/// NC: coordinates known at compile time (0: nc, in chunks). OU, OV, OW as geom_kernel's.
template <int OU, int OV, int OW, int NC>
void value_kernel(const double* net, int nc, const std::array<int, 3>& ord, const double* s, double* f) {
  constexpr int MU = OU ? OU : max_order, MV = OV ? OV : max_order, MW = OW ? OW : max_order;
  const int ou = OU ? OU : ord[0], ov = OV ? OV : ord[1], ow = OW ? OW : ord[2];
  double Bu[MU], Bv[MV], Bw[MW];
  bernstein<OU>(ou, s[0], Bu, nullptr);
  bernstein<OV>(ov, s[1], Bv, nullptr);
  bernstein<OW>(ow, s[2], Bw, nullptr);
  constexpr int chunk = NC ? NC : 16;
  const int n = NC ? NC : nc;  // NC, when given, equals nc: a compile-time stride
  for (int h0 = 0; h0 < n; h0 += chunk) {
    const int hn = NC ? NC : std::min(chunk, n - h0);
    double S[chunk] = {};
    for (int c = 0; c < ow; ++c) {
      double T[chunk] = {};
      for (int b = 0; b < ov; ++b) {
        const double* row = net + static_cast<std::ptrdiff_t>((c * ov + b) * ou) * n + h0;
        double r[chunk] = {};
        for (int a = 0; a < ou; ++a)
          for (int h = 0; h < hn; ++h) r[h] += Bu[a] * row[a * n + h];
        for (int h = 0; h < hn; ++h) T[h] += Bv[b] * r[h];
      }
      for (int h = 0; h < hn; ++h) S[h] += Bw[c] * T[h];
    }
    for (int h = 0; h < hn; ++h) f[h0 + h] = S[h];
  }
}

/// Every coordinate with its first partials for order 4 in all directions (polynomial, NC
/// coordinates per point; the layout of geom_kernel<4, 4, 4, NC, true, NC>): contracted w first, over
/// whole contiguous slabs of the net (4 x 4 points), then v over rows, then u, so that the bulk
/// of the work is long loops of independent multiply-adds that vectorise. The same operations
/// in the same order per coordinate whatever the vector width: the AVX2 and the baseline
/// variants give identical results.
template <int NC>
[[gnu::always_inline]] inline void first_o4_body(const double* net, const double* s, double* f) {
  double Bu[4], Bv[4], Bw[4], dBu[4], dBv[4], dBw[4];
  bernstein<4>(4, s[0], Bu, dBu);
  bernstein<4>(4, s[1], Bv, dBv);
  bernstein<4>(4, s[2], Bw, dBw);
  constexpr int S = 16 * NC, R = 4 * NC;
  double Q0[S], Q1[S];  // sum_c Bw[c] slab_c, sum_c dBw[c] slab_c
  for (int k = 0; k < S; ++k) {
    Q0[k] = Bw[0] * net[k];
    Q1[k] = dBw[0] * net[k];
  }
  for (int c = 1; c < 4; ++c) {
    const double* slab = net + c * S;
    for (int k = 0; k < S; ++k) {
      Q0[k] += Bw[c] * slab[k];
      Q1[k] += dBw[c] * slab[k];
    }
  }
  double R00[R], R01[R], R10[R];  // over v: Bv Q0, dBv Q0, Bv Q1
  for (int k = 0; k < R; ++k) {
    R00[k] = Bv[0] * Q0[k];
    R01[k] = dBv[0] * Q0[k];
    R10[k] = Bv[0] * Q1[k];
  }
  for (int b = 1; b < 4; ++b)
    for (int k = 0; k < R; ++k) {
      R00[k] += Bv[b] * Q0[b * R + k];
      R01[k] += dBv[b] * Q0[b * R + k];
      R10[k] += Bv[b] * Q1[b * R + k];
    }
  for (int h = 0; h < NC; ++h) {
    double v = Bu[0] * R00[h], du = dBu[0] * R00[h], dv = Bu[0] * R01[h], dw = Bu[0] * R10[h];
    for (int a = 1; a < 4; ++a) {
      v += Bu[a] * R00[a * NC + h];
      du += dBu[a] * R00[a * NC + h];
      dv += Bu[a] * R01[a * NC + h];
      dw += Bu[a] * R10[a * NC + h];
    }
    f[h] = v;
    f[NC + h] = du;
    f[2 * NC + h] = dv;
    f[3 * NC + h] = dw;
  }
}

template <int NC>
void first_o4(const double* net, int, const std::array<int, 3>&, const double* s, double* f) {
  first_o4_body<NC>(net, s, f);
}
template <int NC>
[[gnu::target("avx2")]] void first_o4_avx2(const double* net, int, const std::array<int, 3>&, const double* s, double* f) {
  first_o4_body<NC>(net, s, f);
}

template <int NC>
Kernel first_o4_kernel() {
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2 ? first_o4_avx2<NC> : first_o4<NC>;
}

/// Eight doubles as one vector (GCC and Clang vector extensions: two AVX registers, one AVX-512
/// register, four SSE registers; the same IEEE operations lane by lane on every target).
using V8d = double __attribute__((vector_size(64)));

/// Four doubles as one vector (one AVX register): props8_body's operations on the first four
/// lanes, for chunks of at most four points (the same floats lane by lane, at half the work).
using V4d = double __attribute__((vector_size(32)));

/// Properties (coordinates H .. H + m - 1 of an nc-coordinate polynomial net) at eight points at
/// once, one lane per point: s holds the points' local parameters (s[d][lane], not clamped), out
/// the values (out[lane * m + h]). Contracts u, then v, then w, every step one multiply-add of
/// eight lanes; each lane's floats are those of the same operations in the same order, whatever
/// the vector width. OU, OV, OW as geom_kernel's.
template <int OU, int OV, int OW, class V = V8d>
[[gnu::always_inline]] inline void props8_body(const double* net, int nc, int H, int m, const std::array<int, 3>& ord,
                                               const double (*s)[8], double* out) {
  constexpr int MU = OU ? OU : max_order, MV = OV ? OV : max_order, MW = OW ? OW : max_order;
  constexpr int L = sizeof(V) / sizeof(double);
  const int ou = OU ? OU : ord[0], ov = OV ? OV : ord[1], ow = OW ? OW : ord[2];
  V su, sv, sw;
  std::memcpy(&su, s[0], sizeof su);
  std::memcpy(&sv, s[1], sizeof sv);
  std::memcpy(&sw, s[2], sizeof sw);
  V Bu[MU], Bv[MV], Bw[MW];
  bernstein<OU>(ou, su, Bu, nullptr);
  bernstein<OV>(ov, sv, Bv, nullptr);
  bernstein<OW>(ow, sw, Bw, nullptr);
  for (int h = 0; h < m; ++h) {
    V S = {};
    for (int c = 0; c < ow; ++c) {
      V T = {};
      for (int b = 0; b < ov; ++b) {
        const double* row = net + static_cast<std::ptrdiff_t>((c * ov + b) * ou) * nc + H + h;
        V r = Bu[0] * row[0];
        for (int a = 1; a < ou; ++a) r += Bu[a] * row[a * nc];
        T += Bv[b] * r;
      }
      S += Bw[c] * T;
    }
    double v[L];
    std::memcpy(v, &S, sizeof v);
    for (int l = 0; l < L; ++l) out[l * m + h] = v[l];
  }
}

template <int OU, int OV, int OW>
void props8(const double* net, int nc, int H, int m, const std::array<int, 3>& ord, const double (*s)[8], double* out) {
  props8_body<OU, OV, OW>(net, nc, H, m, ord, s, out);
}
template <int OU, int OV, int OW>
[[gnu::target("avx2")]] void props8_avx2(const double* net, int nc, int H, int m, const std::array<int, 3>& ord,
                                         const double (*s)[8], double* out) {
  props8_body<OU, OV, OW>(net, nc, H, m, ord, s, out);
}
template <int OU, int OV, int OW>
[[gnu::target("avx512f")]] void props8_avx512(const double* net, int nc, int H, int m, const std::array<int, 3>& ord,
                                              const double (*s)[8], double* out) {
  props8_body<OU, OV, OW>(net, nc, H, m, ord, s, out);
}

/// props8_body on four lanes (s[d][0..3], out for four points), with AVX2.
template <int OU, int OV, int OW>
[[gnu::target("avx2")]] void props4_avx2(const double* net, int nc, int H, int m, const std::array<int, 3>& ord,
                                         const double (*s)[8], double* out) {
  props8_body<OU, OV, OW, V4d>(net, nc, H, m, ord, s, out);
}

/// props8 for the widest vectors the CPU has.
template <int OU, int OV, int OW>
Props8 props8_for() {
  static const bool avx512 = __builtin_cpu_supports("avx512f") && !std::getenv("TRIVOX_NO_AVX512");
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx512 ? props8_avx512<OU, OV, OW> : avx2 ? props8_avx2<OU, OV, OW> : props8<OU, OV, OW>;
}

template <int OU, int OV, int OW, int H>
Kernels kernels_for(int nc) {
  constexpr bool o4 = OU == 4 && OV == 4 && OW == 4;
  Kernels k{geom_kernel<OU, OV, OW, H, true>, geom_kernel<OU, OV, OW, H, false>, value_kernel<OU, OV, OW, 0>, nullptr,
            H == 3 ? props8_for<OU, OV, OW>() : nullptr};
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (H == 3 && avx2) k.props4 = props4_avx2<OU, OV, OW>;
  [&]<int... I>(std::integer_sequence<int, I...>) {
    (((nc == I + 3) ? (k.all = value_kernel<OU, OV, OW, I + 3>,
                       k.all_first = H != 3 ? nullptr : o4 ? first_o4_kernel<I + 3>() : geom_kernel<OU, OV, OW, I + 3, true, I + 3>, 0)
                    : 0),
     ...);
  }(std::make_integer_sequence<int, 8>{});
  return k;
}

}  // namespace

template <int H>
Kernels pick_kernels(const std::array<int, 3>& ord, int nc) {
  const auto is = [&](int a, int b, int c) { return ord[0] == a && ord[1] == b && ord[2] == c; };
  if (is(2, 2, 2)) return kernels_for<2, 2, 2, H>(nc);
  if (is(3, 3, 3)) return kernels_for<3, 3, 3, H>(nc);
  if (is(4, 4, 4)) return kernels_for<4, 4, 4, H>(nc);
  if (is(4, 4, 2)) return kernels_for<4, 4, 2, H>(nc);
  if (is(2, 2, 4)) return kernels_for<2, 2, 4, H>(nc);
  return kernels_for<0, 0, 0, H>(nc);
}

template Kernels pick_kernels<3>(const std::array<int, 3>& ord, int nc);
template Kernels pick_kernels<4>(const std::array<int, 3>& ord, int nc);

}  // namespace trivox::slice::detail
