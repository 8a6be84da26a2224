#include "trivox/slice/locator.hpp"

#include <tbb/parallel_for.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <mutex>
#include <numeric>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "trivox/error.hpp"
#include "trivox/geom/closest_point.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::slice {

namespace {

constexpr int max_order = 32;  // fillets composed from bicubic faces have order 19
constexpr double inf = std::numeric_limits<double>::infinity();

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

using Kernel = void (*)(const double*, int, const std::array<int, 3>&, const double*, double*);

template <int NC>
Kernel first_o4_kernel() {
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2 ? first_o4_avx2<NC> : first_o4<NC>;
}

/// Eight doubles as one vector (GCC and Clang vector extensions: two AVX registers, one AVX-512
/// register, four SSE registers; the same IEEE operations lane by lane on every target).
using V8d = double __attribute__((vector_size(64)));

/// Properties (coordinates H .. H + m - 1 of an nc-coordinate polynomial net) at eight points at
/// once, one lane per point: s holds the points' local parameters (s[d][lane], not clamped), out
/// the values (out[lane * m + h]). Contracts u, then v, then w, every step one multiply-add of
/// eight lanes; each lane's floats are those of the same operations in the same order, whatever
/// the vector width. OU, OV, OW as geom_kernel's.
/// Four doubles as one vector (one AVX register): props8_body's operations on the first four
/// lanes, for chunks of at most four points (the same floats lane by lane, at half the work).
using V4d = double __attribute__((vector_size(32)));

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

using Props8 = void (*)(const double*, int, int, int, const std::array<int, 3>&, const double (*)[8], double*);

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

struct Kernels {
  Kernel first = nullptr;      ///< geometry with first partials
  Kernel value = nullptr;      ///< geometry value
  Kernel all = nullptr;        ///< every coordinate's value
  Kernel all_first = nullptr;  ///< every coordinate with first partials (polynomial, nc <= 10)
  Props8 props = nullptr;      ///< the properties at eight points (polynomial)
  Props8 props4 = nullptr;     ///< the same at four points (AVX2; else null)
};

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

/// Kernels with the orders fixed at compile time for the common pieces: uniform orders 2 to 4,
/// and the shells and tubes the scenes build (cubic faces swept linearly, (4, 4, 2); linear
/// sections swept along a cubic, (2, 2, 4)); any other orders read them at run time.
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

// ---------------------------------------------------------------------------------------------
// Bezier restriction (de Casteljau), for building leaves: the net of a piece restricted to a
// sub-box of its local [0,1]^3.

/// Both halves of a net split at the middle of direction d, from one de Casteljau triangle per
/// line: the same values as de Casteljau's restrictions to [0, 1/2] and to [1/2, 1] (each step
/// 0.5 x + 0.5 y, x the point of lower index), at half the work of the two restrictions.
/// @param P     the net: H coordinates per point, u fastest, orders ord
/// @param L, R  the halves (as many values as P), written
void split_half(const double* P, const std::array<int, 3>& ord, int H, int d, double* L, double* R) {
  // Along d the net is `outer` blocks of n rows of `inner` contiguous values.
  const int n = ord[static_cast<std::size_t>(d)];
  const int inner = H * (d == 0 ? 1 : d == 1 ? ord[0] : ord[0] * ord[1]);
  const int outer = d == 0 ? ord[1] * ord[2] : d == 1 ? ord[2] : 1;
  const std::ptrdiff_t block = static_cast<std::ptrdiff_t>(n) * inner;
  for (int o = 0; o < outer; ++o) {
    const double* p = P + o * block;
    double* l = L + o * block;
    double* r = R + o * block;  // the triangle's working rows; row i ends as the right half's
    std::copy(p, p + inner, l);
    if (n == 1) std::copy(p, p + inner, r);
    for (int k = 1; k < n; ++k) {
      if (k == 1) {  // the first stage reads P
        for (int j = 0; j < n - 1; ++j) {
          const double* pj = p + static_cast<std::ptrdiff_t>(j) * inner;
          const double* pj1 = pj + inner;
          double* rj = r + static_cast<std::ptrdiff_t>(j) * inner;
          for (int e = 0; e < inner; ++e) rj[e] = 0.5 * pj[e] + 0.5 * pj1[e];
        }
        std::copy(p + block - inner, p + block, r + block - inner);
        std::copy(r, r + inner, l + inner);
        continue;
      }
      for (int j = 0; j < n - k; ++j) {
        double* rj = r + static_cast<std::ptrdiff_t>(j) * inner;
        const double* rj1 = rj + inner;
        for (int e = 0; e < inner; ++e) rj[e] = 0.5 * rj[e] + 0.5 * rj1[e];
      }
      std::copy(r, r + inner, l + static_cast<std::ptrdiff_t>(k) * inner);
    }
  }
}

struct Flatness {
  double deviation = 0.0;  ///< max distance of a control point from the least-squares affine map
  double diagonal = 0.0;   ///< of the control points' box
  Vec3 box_lo{}, box_hi{};
  /// The parallelepiped of the affine map's frame that holds every control point (see LocatorLeaf).
  Vec3 origin{}, frame_lo{}, frame_hi{};
  std::array<Vec3, 3> frame{};  ///< rows of the inverse of the affine map's matrix
};

/// What the least-squares affine fit of nets of one order needs beyond the net: the control
/// points' Greville abscissae i / (order - 1), centred, per direction (a tensor grid, so the fit
/// separates per direction), and their squared sums over the grid. One per piece.
struct FitTables {
  std::array<int, 3> ord{};
  int n = 0;
  std::array<std::vector<double>, 3> xi;
  Vec3 den{};

  explicit FitTables(const std::array<int, 3>& o) : ord(o), n(o[0] * o[1] * o[2]) {
    for (std::size_t d = 0; d < 3; ++d) {
      xi[d].resize(static_cast<std::size_t>(o[d]));
      for (int j = 0; j < o[d]; ++j) xi[d][static_cast<std::size_t>(j)] = o[d] > 1 ? double(j) / (o[d] - 1) - 0.5 : 0.0;
    }
    // Summed over the grid point after point (u fastest), as the fit sums.
    for (int c = 0; c < o[2]; ++c)
      for (int b = 0; b < o[1]; ++b)
        for (int a = 0; a < o[0]; ++a) {
          const double x[3] = {xi[0][static_cast<std::size_t>(a)], xi[1][static_cast<std::size_t>(b)], xi[2][static_cast<std::size_t>(c)]};
          for (std::size_t d = 0; d < 3; ++d) den[d] += x[d] * x[d];
        }
  }
};

/// The least-squares affine map of a net's control points X (xyz, 3 per point) against their
/// Greville abscissae: X ~ mean + sum_d A[d] xi_d, and the largest distance of a point from it.
struct AffineFit {
  Vec3 mean{};
  std::array<Vec3, 3> A{};  ///< A[d]: the xyz change per unit of direction d
  double deviation = 0.0;
};

AffineFit affine_fit(const double* X, const FitTables& T) {
  // Every sum in local variables, so that the chains of dependent additions stay in registers.
  const int n = T.n;
  double m0 = 0.0, m1 = 0.0, m2 = 0.0;
  if (n & (n - 1)) {
    const double nd = n;
    for (int i = 0; i < n; ++i) {
      m0 += X[3 * i] / nd;
      m1 += X[3 * i + 1] / nd;
      m2 += X[3 * i + 2] / nd;
    }
  } else {  // x / 2^k == x * 2^-k exactly: no divisions (orders 2 and 4)
    const double r = 1.0 / n;
    for (int i = 0; i < n; ++i) {
      m0 += X[3 * i] * r;
      m1 += X[3 * i + 1] * r;
      m2 += X[3 * i + 2] * r;
    }
  }
  const double* x0 = T.xi[0].data();
  const double* x1 = T.xi[1].data();
  const double* x2 = T.xi[2].data();
  const int ou = T.ord[0], ov = T.ord[1], ow = T.ord[2];
  double a00 = 0.0, a01 = 0.0, a02 = 0.0, a10 = 0.0, a11 = 0.0, a12 = 0.0, a20 = 0.0, a21 = 0.0, a22 = 0.0;
  const double* p = X;
#if defined(__SSE2__)
  {
    // The x and y slopes of each direction in the lanes of one register: the same sums.
    const __m128d vm01 = _mm_set_pd(m1, m0);
    __m128d s0 = _mm_setzero_pd(), s1 = _mm_setzero_pd(), s2 = _mm_setzero_pd();  // (a_d0, a_d1)
    for (int c = 0; c < ow; ++c)
      for (int b = 0; b < ov; ++b) {
        const __m128d y1 = _mm_set1_pd(x1[b]), y2 = _mm_set1_pd(x2[c]);
        for (int a = 0; a < ou; ++a, p += 3) {
          const __m128d e01 = _mm_sub_pd(_mm_loadu_pd(p), vm01);
          const double e2 = p[2] - m2;
          s0 = _mm_add_pd(s0, _mm_mul_pd(_mm_set1_pd(x0[a]), e01));
          s1 = _mm_add_pd(s1, _mm_mul_pd(y1, e01));
          s2 = _mm_add_pd(s2, _mm_mul_pd(y2, e01));
          a02 += x0[a] * e2;
          a12 += x1[b] * e2;
          a22 += x2[c] * e2;
        }
      }
    double l[2];
    _mm_storeu_pd(l, s0);
    a00 = l[0], a01 = l[1];
    _mm_storeu_pd(l, s1);
    a10 = l[0], a11 = l[1];
    _mm_storeu_pd(l, s2);
    a20 = l[0], a21 = l[1];
  }
#else
  for (int c = 0; c < ow; ++c)
    for (int b = 0; b < ov; ++b)
      for (int a = 0; a < ou; ++a, p += 3) {
        const double e0 = p[0] - m0, e1 = p[1] - m1, e2 = p[2] - m2;
        a00 += x0[a] * e0;
        a10 += x1[b] * e0;
        a20 += x2[c] * e0;
        a01 += x0[a] * e1;
        a11 += x1[b] * e1;
        a21 += x2[c] * e1;
        a02 += x0[a] * e2;
        a12 += x1[b] * e2;
        a22 += x2[c] * e2;
      }
#endif
  if (T.den[0] > 0.0) a00 /= T.den[0], a01 /= T.den[0], a02 /= T.den[0];
  if (T.den[1] > 0.0) a10 /= T.den[1], a11 /= T.den[1], a12 /= T.den[1];
  if (T.den[2] > 0.0) a20 /= T.den[2], a21 /= T.den[2], a22 /= T.den[2];
  // The largest squared distance, then one root (the root is monotonic: the same maximum).
  double dev2_max = 0.0;
  p = X;
  // A point's squared distance from the fit (the tail of a row, or every point without SSE2).
  const auto point_dev2 = [&](const double* q, int a, int b, int c) {
    const double e0 = q[0] - m0 - a00 * x0[a] - a10 * x1[b] - a20 * x2[c];
    const double e1 = q[1] - m1 - a01 * x0[a] - a11 * x1[b] - a21 * x2[c];
    const double e2 = q[2] - m2 - a02 * x0[a] - a12 * x1[b] - a22 * x2[c];
    double dev2 = 0.0;
    dev2 += e0 * e0;
    dev2 += e1 * e1;
    dev2 += e2 * e2;
    return dev2;
  };
#if defined(__SSE2__)
  // Two points at a time along u, one per lane: the same operations per point. Lanes keep
  // their own maxima (neither takes a NaN: maxpd returns its second operand then, as std::max).
  const __m128d vm0 = _mm_set1_pd(m0), vm1 = _mm_set1_pd(m1), vm2 = _mm_set1_pd(m2);
  const __m128d v00 = _mm_set1_pd(a00), v10 = _mm_set1_pd(a10), v20 = _mm_set1_pd(a20);
  const __m128d v01 = _mm_set1_pd(a01), v11 = _mm_set1_pd(a11), v21 = _mm_set1_pd(a21);
  const __m128d v02 = _mm_set1_pd(a02), v12 = _mm_set1_pd(a12), v22 = _mm_set1_pd(a22);
  __m128d vmax = _mm_setzero_pd();
  for (int c = 0; c < ow; ++c)
    for (int b = 0; b < ov; ++b) {
      const __m128d y1 = _mm_set1_pd(x1[b]), y2 = _mm_set1_pd(x2[c]);
      int a = 0;
      for (; a + 1 < ou; a += 2, p += 6) {
        const __m128d q01 = _mm_loadu_pd(p), q23 = _mm_loadu_pd(p + 2), q45 = _mm_loadu_pd(p + 4);
        const __m128d X0 = _mm_shuffle_pd(q01, q23, 2), X1 = _mm_shuffle_pd(q01, q45, 1), X2 = _mm_shuffle_pd(q23, q45, 2);
        const __m128d y0 = _mm_loadu_pd(x0 + a);
        const __m128d e0 = _mm_sub_pd(_mm_sub_pd(_mm_sub_pd(_mm_sub_pd(X0, vm0), _mm_mul_pd(v00, y0)), _mm_mul_pd(v10, y1)), _mm_mul_pd(v20, y2));
        const __m128d e1 = _mm_sub_pd(_mm_sub_pd(_mm_sub_pd(_mm_sub_pd(X1, vm1), _mm_mul_pd(v01, y0)), _mm_mul_pd(v11, y1)), _mm_mul_pd(v21, y2));
        const __m128d e2 = _mm_sub_pd(_mm_sub_pd(_mm_sub_pd(_mm_sub_pd(X2, vm2), _mm_mul_pd(v02, y0)), _mm_mul_pd(v12, y1)), _mm_mul_pd(v22, y2));
        // 0 + e0^2 == e0^2 exactly (a square is +0 or more, or NaN): the sum from its first term.
        const __m128d dev2 = _mm_add_pd(_mm_add_pd(_mm_mul_pd(e0, e0), _mm_mul_pd(e1, e1)), _mm_mul_pd(e2, e2));
        vmax = _mm_max_pd(dev2, vmax);
      }
      for (; a < ou; ++a, p += 3) dev2_max = std::max(dev2_max, point_dev2(p, a, b, c));
    }
  double lanes[2];
  _mm_storeu_pd(lanes, vmax);
  dev2_max = std::max(dev2_max, std::max(lanes[0], lanes[1]));
#else
  for (int c = 0; c < ow; ++c)
    for (int b = 0; b < ov; ++b)
      for (int a = 0; a < ou; ++a, p += 3) dev2_max = std::max(dev2_max, point_dev2(p, a, b, c));
#endif
  AffineFit f;
  f.mean = {m0, m1, m2};
  f.A = {Vec3{a00, a01, a02}, Vec3{a10, a11, a12}, Vec3{a20, a21, a22}};
  f.deviation = std::sqrt(dev2_max);
  return f;
}

/// The control points' xyz box and its diagonal.
void control_box(const double* X, int n, Flatness& f) {
  f.box_lo = {inf, inf, inf};
  f.box_hi = {-inf, -inf, -inf};
  for (int i = 0; i < n; ++i)
    for (std::size_t d = 0; d < 3; ++d) {
      f.box_lo[d] = std::min(f.box_lo[d], X[3 * i + static_cast<int>(d)]);
      f.box_hi[d] = std::max(f.box_hi[d], X[3 * i + static_cast<int>(d)]);
    }
  double diag2 = 0.0;
  for (std::size_t d = 0; d < 3; ++d) diag2 += (f.box_hi[d] - f.box_lo[d]) * (f.box_hi[d] - f.box_lo[d]);
  f.diagonal = std::sqrt(diag2);
}

/// The parallelepiped of the fit's frame that holds the control points X: the frame is the
/// inverse of [A0 A1 A2] (rows = cross products / det), or the identity when the affine map is
/// (nearly) degenerate.
void fit_frame(const double* X, int n, const AffineFit& fit, Flatness& f) {
  const auto& A = fit.A;
  auto cross = [](const Vec3& a, const Vec3& b) { return Vec3{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}; };
  auto len = [](const Vec3& a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); };
  const Vec3 c0 = cross(A[1], A[2]), c1 = cross(A[2], A[0]), c2 = cross(A[0], A[1]);
  const double det = A[0][0] * c0[0] + A[0][1] * c0[1] + A[0][2] * c0[2];
  if (std::abs(det) > 1e-6 * len(A[0]) * len(A[1]) * len(A[2]) && std::isfinite(det)) {
    for (std::size_t k = 0; k < 3; ++k) {
      f.frame[0][k] = c0[k] / det;
      f.frame[1][k] = c1[k] / det;
      f.frame[2][k] = c2[k] / det;
    }
  } else {
    f.frame = {Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}};
  }
  const Vec3& mean = fit.mean;
  f.origin = mean;
  f.frame_lo = {inf, inf, inf};
  f.frame_hi = {-inf, -inf, -inf};
  for (int i = 0; i < n; ++i) {
    const double* x = X + 3 * i;
    for (std::size_t k = 0; k < 3; ++k) {
      const double c = f.frame[k][0] * (x[0] - mean[0]) + f.frame[k][1] * (x[1] - mean[1]) + f.frame[k][2] * (x[2] - mean[2]);
      f.frame_lo[k] = std::min(f.frame_lo[k], c);
      f.frame_hi[k] = std::max(f.frame_hi[k], c);
    }
  }
}

/// The xyz of a geometry net's control points (3 per point): the net itself when polynomial
/// (H = 3), else into `buf` (n * 3 values) divided by the weights.
const double* cartesian_points(const double* net, int n, int H, double* buf) {
  if (H == 3) return net;
  for (int i = 0; i < n; ++i) {
    const double* q = net + 4 * i;
    for (int k = 0; k < 3; ++k) buf[3 * i + k] = q[k] / q[3];
  }
  return buf;
}

// ---------------------------------------------------------------------------------------------
// Small dense linear algebra.

inline double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline double norm3(const double* a) { return std::sqrt(dot3(a, a)); }

/// Solves J d = r for d, J given by its columns. Falls back to a Levenberg-Marquardt step when J
/// is (nearly) singular.
void solve3(const double J[3][3], const double* r, double* d) {
  // columns J[0], J[1], J[2]; J * d = sum_k d_k J[k]
  const double c0[3] = {J[1][1] * J[2][2] - J[1][2] * J[2][1], J[1][2] * J[2][0] - J[1][0] * J[2][2],
                        J[1][0] * J[2][1] - J[1][1] * J[2][0]};  // J[1] x J[2]
  const double det = dot3(J[0], c0);
  const double scale = norm3(J[0]) * norm3(J[1]) * norm3(J[2]);
  if (std::abs(det) > 1e-12 * scale) {
    // Cramer: d_k = det(J with column k replaced by r) / det
    const double c1[3] = {J[2][1] * J[0][2] - J[2][2] * J[0][1], J[2][2] * J[0][0] - J[2][0] * J[0][2],
                          J[2][0] * J[0][1] - J[2][1] * J[0][0]};  // J[2] x J[0]
    const double c2[3] = {J[0][1] * J[1][2] - J[0][2] * J[1][1], J[0][2] * J[1][0] - J[0][0] * J[1][2],
                          J[0][0] * J[1][1] - J[0][1] * J[1][0]};  // J[0] x J[1]
    d[0] = dot3(r, c0) / det;
    d[1] = dot3(r, c1) / det;
    d[2] = dot3(r, c2) / det;
    return;
  }
  // (J^T J + mu I) d = J^T r
  double A[3][3], b[3];
  double tr = 0.0;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) A[i][j] = dot3(J[i], J[j]);
    b[i] = dot3(J[i], r);
    tr += A[i][i];
  }
  const double mu = 1e-9 * tr + std::numeric_limits<double>::min();
  for (int i = 0; i < 3; ++i) A[i][i] += mu;
  // Cholesky-free: Cramer on the SPD system
  const double m0[3] = {A[1][1] * A[2][2] - A[1][2] * A[2][1], A[1][2] * A[2][0] - A[1][0] * A[2][2],
                        A[1][0] * A[2][1] - A[1][1] * A[2][0]};
  const double dA = A[0][0] * m0[0] + A[0][1] * m0[1] + A[0][2] * m0[2];
  if (!(std::abs(dA) > 0.0)) {
    d[0] = d[1] = d[2] = 0.0;
    return;
  }
  const double m1[3] = {A[2][1] * A[0][2] - A[2][2] * A[0][1], A[2][2] * A[0][0] - A[2][0] * A[0][2],
                        A[2][0] * A[0][1] - A[2][1] * A[0][0]};
  const double m2[3] = {A[0][1] * A[1][2] - A[0][2] * A[1][1], A[0][2] * A[1][0] - A[0][0] * A[1][2],
                        A[0][0] * A[1][1] - A[0][1] * A[1][0]};
  d[0] = dot3(b, m0) / dA;
  d[1] = dot3(b, m1) / dA;
  d[2] = dot3(b, m2) / dA;
}

/// Least squares over the free columns only (the others' steps are zero): min |sum_free d_k J_k - r|.
void solve_free(const double J[3][3], const double* r, const bool* free, double* d) {
  int idx[3], n = 0;
  for (int k = 0; k < 3; ++k) {
    d[k] = 0.0;
    if (free[k]) idx[n++] = k;
  }
  if (n == 0) return;
  if (n == 3) return solve3(J, r, d);
  if (n == 1) {
    const double a = dot3(J[idx[0]], J[idx[0]]);
    if (a > 0.0) d[idx[0]] = dot3(J[idx[0]], r) / a;
    return;
  }
  const double a = dot3(J[idx[0]], J[idx[0]]), b = dot3(J[idx[0]], J[idx[1]]), c = dot3(J[idx[1]], J[idx[1]]);
  const double ra = dot3(J[idx[0]], r), rb = dot3(J[idx[1]], r);
  double det = a * c - b * b;
  const double mu = 1e-12 * (a + c);
  if (!(det > mu * (a + c))) det = (a + mu) * (c + mu) - b * b;
  if (!(det > 0.0)) return;
  d[idx[0]] = (c * ra - b * rb) / det;
  d[idx[1]] = (a * rb - b * ra) / det;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

namespace {
/// A flag for work done once, on first use, by whichever thread comes first: std::call_once
/// behind an acquire load, since libstdc++'s call_once sets up thread-local state on every call,
/// even long after the work is done (the sampler asks for bounds at every anchor).
struct Once {
  std::atomic<bool> done{false};
  std::once_flag flag;

  template <class F>
  void operator()(F&& f) {
    if (done.load(std::memory_order_acquire)) return;
    std::call_once(flag, [&] {
      f();
      done.store(true, std::memory_order_release);
    });
  }
};
}  // namespace

struct Locator::Data {
  struct Piece {
    int cell = 0;
    std::array<int, 3> order{};
    Vec3 lo{}, len{}, inv_len{};  ///< global parameter box of the piece
    int H = 3;                    ///< geometry coordinates: 3 polynomial, 4 rational (wx wy wz w)
    int nc = 3;                   ///< coordinates per control point: H + properties (times w)
    Kernels k;
    std::size_t net = 0;  ///< offset into the pool
    Vec3 lipschitz{};     ///< bounds on |dX/dt_d| (global parameters); inf if rational
    /// Second-derivative bounds (polynomial pieces with all_first): computed on first use,
    /// under bounds_once (a job touches only some pieces; the values do not depend on which
    /// thread computes them).
    mutable StepBounds bounds;
  };
  struct Cell {
    std::array<std::vector<double>, 3> breaks;  ///< distinct knots inside the domain
    std::array<int, 3> spans{};
    int first_piece = 0;
    Vec3 lo{}, hi{};
  };
  struct Node {
    Vec3 lo{}, hi{};
    int left = -1, right = -1;  ///< children, or -1 for a leaf node
    int first = 0, count = 0;   ///< range of items for a leaf node
  };

  /// A trimmed cell's conditions (VCell::within, VCell::without), each a locator over its own
  /// cells; null for plain cells.
  struct Sub {
    vmodel::VModel model;
    std::unique_ptr<Locator> loc;
  };
  struct Trim {
    std::vector<std::unique_ptr<Sub>> within, without;
    vmodel::BlendRule blend = vmodel::BlendRule::first;
    double power = 1.0;
    /// BlendRule::distance: per blended value, its input's boundary (empty otherwise).
    std::vector<std::vector<geom::SurfaceDistance>> boundaries;
  };

  int m = 0;  ///< properties per point
  std::vector<std::unique_ptr<Trim>> trims;  ///< per cell
  bool any_trim = false;
  std::vector<Cell> cells;
  std::vector<Piece> pieces;
  std::unique_ptr<Once[]> bounds_once;  ///< one per piece: its bounds computed
  std::vector<double> pool;  ///< every piece's net, control point after control point
  std::vector<LocatorLeaf> leaves;
  std::vector<Node> nodes;
  std::vector<int> items;  ///< leaf indices in BVH order

  const Piece& piece_at(int cell, const Vec3& t) const noexcept {
    const Cell& c = cells[static_cast<std::size_t>(cell)];
    int idx[3];
    for (int d = 0; d < 3; ++d) {
      const auto& br = c.breaks[static_cast<std::size_t>(d)];
      const int n = c.spans[static_cast<std::size_t>(d)];
      if (n == 1) {
        idx[d] = 0;
        continue;
      }
      const auto it = std::upper_bound(br.begin() + 1, br.begin() + n, t[static_cast<std::size_t>(d)]);
      idx[d] = static_cast<int>(it - br.begin()) - 1;
    }
    return pieces[static_cast<std::size_t>(c.first_piece + idx[0] + c.spans[0] * (idx[1] + c.spans[1] * idx[2]))];
  }

  static void local(const Piece& pc, const Vec3& t, double* s) noexcept {
    for (std::size_t d = 0; d < 3; ++d) s[d] = std::clamp((t[d] - pc.lo[d]) * pc.inv_len[d], 0.0, 1.0);
  }

  /// X (3) and, with J, the Jacobian columns J[d] = dX/dt_d (global parameters) at t.
  void eval_geom(const Piece& pc, const Vec3& t, double* X, double (*J)[3]) const noexcept {
    double s[3], f[16];
    local(pc, t, s);
    (J ? pc.k.first : pc.k.value)(pool.data() + pc.net, pc.nc, pc.order, s, f);
    if (pc.H == 3) {
      for (int h = 0; h < 3; ++h) X[h] = f[h];
      if (J)
        for (std::size_t d = 0; d < 3; ++d)
          for (std::size_t h = 0; h < 3; ++h) J[d][h] = f[3 * (d + 1) + h] * pc.inv_len[d];
      return;
    }
    const double iw = 1.0 / f[3];
    for (int h = 0; h < 3; ++h) X[h] = f[h] * iw;
    if (J)
      for (std::size_t d = 0; d < 3; ++d) {
        const double* fd = f + 4 * (d + 1);
        for (std::size_t h = 0; h < 3; ++h) J[d][h] = (fd[h] - X[h] * fd[3]) * iw * pc.inv_len[d];
      }
  }

  /// xyz (3) and the m properties of piece pc at t, in one pass over its net.
  /// @param buf  pc.nc values of scratch
  template <class T>
  void eval_all(const Piece& pc, const Vec3& t, double* buf, double* X, T* props) const noexcept {
    double s[3];
    local(pc, t, s);
    pc.k.all(pool.data() + pc.net, pc.nc, pc.order, s, buf);
    const double iw = pc.H == 4 ? 1.0 / buf[3] : 1.0;
    for (int h = 0; h < 3; ++h) X[h] = buf[h] * iw;
    if (props)
      for (int h = 0; h < m; ++h) props[h] = static_cast<T>(buf[pc.H + h] * iw);
  }
};

/// Scratch for Data::eval_all: on the stack for up to 64 coordinates.
class Scratch {
public:
  explicit Scratch(int n) {
    if (n > 64) heap_.resize(static_cast<std::size_t>(n));
  }
  double* data() noexcept { return heap_.empty() ? stack_ : heap_.data(); }

private:
  double stack_[64];
  std::vector<double> heap_;
};

// ---------------------------------------------------------------------------------------------
// Construction.

namespace {

using Data = Locator::Data;

/// A leaf of build_leaves: its box in the piece's local [0,1]^3 and its regions.
struct LeafBox {
  Vec3 lo, hi;
  Flatness f;
};

/// Subdivides a piece's parameter box (local [0,1]^3) into nearly affine leaves: deviation from
/// affine at most 10% of the leaf's diagonal and, when `max_dev` > 0, at most max_dev; then, when
/// 0 < fine_dev < max_dev, on towards fine_dev with at most fine_factor times as many leaves
/// (the most deviating split first, so a budget that runs out leaves the piece evenly refined).
/// Cost per split: one de Casteljau triangle and one or two affine fits per direction tried; the
/// frames only for the leaves. Nets live in one slab of reused slots (no allocation per split).
/// @param net  the piece's geometry net: H coordinates per control point, u fastest
void build_leaves(const double* net, const std::array<int, 3>& ord, int H, double min_diag, double max_dev, double fine_dev,
                  int fine_factor, int max_leaves, std::vector<LeafBox>& out) {
  constexpr double flat = 0.1;  // deviation / diagonal at which a leaf is flat enough
  const FitTables T(ord);
  const int n = T.n;
  const std::size_t size = static_cast<std::size_t>(n) * static_cast<std::size_t>(H);
  struct Item {
    Vec3 lo, hi;
    int slot;  // its net in the slab
    AffineFit fit;
    Flatness f;  // deviation, diagonal and box; the frame is filled for the leaves at the end
  };
  std::vector<double> slab;
  std::vector<int> free_slots;
  auto take = [&] {
    if (!free_slots.empty()) {
      const int s = free_slots.back();
      free_slots.pop_back();
      return s;
    }
    const int s = static_cast<int>(slab.size() / size);
    slab.resize(slab.size() + size);
    return s;
  };
  auto at = [&](int slot) { return slab.data() + static_cast<std::ptrdiff_t>(slot) * static_cast<std::ptrdiff_t>(size); };
  std::vector<double> xyz(H == 3 ? 0 : static_cast<std::size_t>(n) * 3);  // cartesian points of rational nets
  auto points = [&](int slot) { return cartesian_points(at(slot), n, H, xyz.data()); };

  // The heap and the lists hold small records (deviation, item); the items stay in place.
  struct Ref {
    double deviation;
    int item;
  };
  auto less = [](const Ref& a, const Ref& b) { return a.deviation < b.deviation; };
  std::vector<Item> items;
  std::vector<Ref> work, done;
  // Splits the most deviating item until every one is flat enough for dev_limit or the budget
  // of `cap` leaves is spent.
  auto refine = [&](double dev_limit, int cap) {
    while (!work.empty()) {
      std::pop_heap(work.begin(), work.end(), less);
      const Ref ref = work.back();
      work.pop_back();
      const Item& it = items[static_cast<std::size_t>(ref.item)];
      const bool flat_enough = it.f.deviation <= flat * it.f.diagonal && (dev_limit <= 0.0 || it.f.deviation <= dev_limit);
      const bool stop = flat_enough || it.f.diagonal < min_diag || static_cast<int>(done.size() + work.size()) + 2 > cap;
      if (stop) {
        done.push_back(ref);
        continue;
      }
      // Split the direction whose halves come out flattest (absolute deviation: splitting a
      // direction along which the net is already straight leaves the deviation as it is). A
      // direction whose first half already deviates as much as the best so far cannot win.
      int best = -1;
      double best_dev = inf;
      int best_slots[2] = {take(), take()}, try_slots[2] = {take(), take()};
      AffineFit best_fit[2], try_fit[2];
      for (int d = 0; d < 3; ++d) {
        if (ord[static_cast<std::size_t>(d)] < 2) continue;
        split_half(at(it.slot), ord, H, d, at(try_slots[0]), at(try_slots[1]));
        double dev = 0.0;
        for (int side = 0; side < 2 && dev < best_dev; ++side) {
          try_fit[side] = affine_fit(points(try_slots[side]), T);
          dev = std::max(dev, try_fit[side].deviation);
        }
        if (dev < best_dev) {
          best_dev = dev;
          best = d;
          std::swap(best_slots, try_slots);
          std::swap(best_fit, try_fit);
        }
      }
      free_slots.push_back(try_slots[0]);
      free_slots.push_back(try_slots[1]);
      if (best < 0) {
        free_slots.push_back(best_slots[0]);
        free_slots.push_back(best_slots[1]);
        done.push_back(ref);
        continue;
      }
      free_slots.push_back(it.slot);
      const Vec3 lo = it.lo, hi = it.hi;  // `it` dies when items grows
      for (int side = 0; side < 2; ++side) {
        Item child;
        child.slot = best_slots[side];
        child.fit = best_fit[side];
        child.f.deviation = child.fit.deviation;
        control_box(points(child.slot), n, child.f);
        child.lo = lo;
        child.hi = hi;
        const double mid = 0.5 * (lo[static_cast<std::size_t>(best)] + hi[static_cast<std::size_t>(best)]);
        (side ? child.lo : child.hi)[static_cast<std::size_t>(best)] = mid;
        items.push_back(child);
        work.push_back({child.f.deviation, static_cast<int>(items.size()) - 1});
        std::push_heap(work.begin(), work.end(), less);
      }
    }
  };
  {
    Item root{{0, 0, 0}, {1, 1, 1}, take(), {}, {}};
    std::copy(net, net + size, at(root.slot));
    root.fit = affine_fit(points(root.slot), T);
    root.f.deviation = root.fit.deviation;
    control_box(points(root.slot), n, root.f);
    items.push_back(root);
    work.push_back({root.f.deviation, 0});
  }
  refine(max_dev, max_leaves);
  if (fine_dev > 0.0 && (max_dev <= 0.0 || fine_dev < max_dev) && fine_factor > 1) {
    const int cap = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(max_leaves), done.size() * static_cast<std::size_t>(fine_factor)));
    work = std::move(done);
    done.clear();
    std::make_heap(work.begin(), work.end(), less);
    refine(fine_dev, cap);
  }
  out.reserve(out.size() + done.size());
  for (const auto& ref : done) {
    auto& it = items[static_cast<std::size_t>(ref.item)];
    fit_frame(points(it.slot), n, it.fit, it.f);
    out.push_back({it.lo, it.hi, it.f});
  }
}

/// Bounds on the second partials of a polynomial piece (net: nc = 3 + m coordinates per point):
/// d^2/dt_d dt_e is a Bezier polynomial with control points (scaled) second differences of the
/// net, so their largest norm bounds it (convex hull property). The largest squared norm is
/// kept and its root taken once (the root is monotonic: the same bound).
StepBounds second_derivative_bounds(const double* net, const Data::Piece& pc) {
  StepBounds b;
  b.valid = true;
  for (std::size_t d = 0; d < 3; ++d) {
    b.lo[d] = pc.lo[d];
    b.hi[d] = pc.lo[d] + pc.len[d];
  }
  const auto& o = pc.order;
  const int nc = pc.nc;
  const int stride[3] = {1, o[0], o[0] * o[1]};
  for (int d = 0; d < 3; ++d)
    for (int e = d; e < 3; ++e) {
      const auto ud = static_cast<std::size_t>(d), ue = static_cast<std::size_t>(e);
      const double factor = d == e ? (o[ud] - 1.0) * (o[ud] - 2.0) * pc.inv_len[ud] * pc.inv_len[ud]
                                   : (o[ud] - 1.0) * (o[ue] - 1.0) * pc.inv_len[ud] * pc.inv_len[ue];
      double bx2 = 0.0, bp = 0.0, bv[3] = {0.0, 0.0, 0.0};
      // The second difference at point i, over the points where it exists: d == e: P_i -
      // 2 P_i+s + P_i+2s; d != e: P_i - P_i+sd - P_i+se + P_i+sd+se (in this order; only their
      // magnitudes are used).
      std::array<int, 3> lim = o;
      std::ptrdiff_t o1, o2, o3 = 0;
      if (d == e) {
        lim[ud] -= 2;
        o1 = static_cast<std::ptrdiff_t>(stride[d]) * nc;
        o2 = 2 * o1;
      } else {
        lim[ud] -= 1;
        lim[ue] -= 1;
        o1 = static_cast<std::ptrdiff_t>(stride[d]) * nc;
        o2 = static_cast<std::ptrdiff_t>(stride[e]) * nc;
        o3 = o1 + o2;
      }
      if (factor != 0.0)
        for (int c = 0; c < lim[2]; ++c)
          for (int bb = 0; bb < lim[1]; ++bb) {
            const double* p = net + static_cast<std::ptrdiff_t>(o[0] * (bb + o[1] * c)) * nc;
            for (int a = 0; a < lim[0]; ++a, p += nc) {
              double v[3];
              if (d == e)
                for (int h = 0; h < 3; ++h) v[h] = p[h] + -2.0 * p[o1 + h] + p[o2 + h];
              else
                for (int h = 0; h < 3; ++h) v[h] = p[h] - p[o1 + h] - p[o2 + h] + p[o3 + h];
              double x2 = 0.0;
              for (int h = 0; h < 3; ++h) {
                x2 += v[h] * v[h];
                bv[h] = std::max(bv[h], std::abs(v[h]));
              }
              bx2 = std::max(bx2, x2);
              if (d == e)
                for (int h = 3; h < nc; ++h) bp = std::max(bp, std::abs(p[h] + -2.0 * p[o1 + h] + p[o2 + h]));
              else
                for (int h = 3; h < nc; ++h) bp = std::max(bp, std::abs(p[h] - p[o1 + h] - p[o2 + h] + p[o3 + h]));
            }
          }
      const double bx = std::sqrt(bx2);
      // Rounding in the differences is far below these bounds' slack; 1e-12 relative covers it.
      b.b2[ud][ue] = b.b2[ue][ud] = bx * factor * (1.0 + 1e-12);
      for (std::size_t k = 0; k < 3; ++k) b.b2v[ud][ue][k] = b.b2v[ue][ud][k] = bv[k] * factor * (1.0 + 1e-12);
      b.p2[ud][ue] = b.p2[ue][ud] = bp * factor * (1.0 + 1e-12);
    }
  for (std::size_t d = 0; d < 3; ++d)
    b.lip = std::max(b.lip, std::sqrt(b.b2[d][0] * b.b2[d][0] + b.b2[d][1] * b.b2[d][1] + b.b2[d][2] * b.b2[d][2]));
  return b;
}

/// Bounds on the properties' third partials (coordinates 3 .. nc - 1 of a polynomial net), from
/// the convex hull of their third differences: for c_d derivatives along each direction d
/// (c_u + c_v + c_w = 3) the partial is a Bezier polynomial of degrees n_d - c_d whose
/// coefficients are the mixed differences prod_d Delta_d^{c_d} of the control points times
/// prod_d n_d! / (n_d - c_d)! / len_d^{c_d} (n_d = order_d - 1), so their largest magnitude
/// bounds it (zero where some c_d exceeds n_d).
void third_partial_bounds(const double* net, const Data::Piece& pc, StepBounds& b) {
  const auto& o = pc.order;
  const int nc = pc.nc;
  const std::ptrdiff_t stride[3] = {nc, static_cast<std::ptrdiff_t>(o[0]) * nc, static_cast<std::ptrdiff_t>(o[0] * o[1]) * nc};
  for (int d = 0; d < 3; ++d)
    for (int e = d; e < 3; ++e)
      for (int f = e; f < 3; ++f) {
        int c[3] = {0, 0, 0};
        ++c[d], ++c[e], ++c[f];
        double factor = 1.0;
        std::array<int, 3> lim = o;
        for (std::size_t k = 0; k < 3; ++k) {
          const int n = o[k] - 1;
          for (int j = 0; j < c[k]; ++j) factor *= (n - j) * pc.inv_len[k];
          lim[k] -= c[k];
        }
        double bp = 0.0;
        if (factor != 0.0 && lim[0] > 0 && lim[1] > 0 && lim[2] > 0) {
          // The offsets and signs of the mixed difference: prod_k sum_j (-1)^(c_k - j) C(c_k, j) at +j along k.
          std::vector<std::pair<std::ptrdiff_t, double>> terms{{0, 1.0}};
          for (std::size_t k = 0; k < 3; ++k)
            for (int r = 0; r < c[k]; ++r) {  // one more first difference along k: x(+1) - x
              std::vector<std::pair<std::ptrdiff_t, double>> next;
              for (const auto& [off, w] : terms) {
                next.push_back({off + stride[k], w});
                next.push_back({off, -w});
              }
              terms = std::move(next);
            }
          for (int cw = 0; cw < lim[2]; ++cw)
            for (int cv = 0; cv < lim[1]; ++cv)
              for (int cu = 0; cu < lim[0]; ++cu) {
                const double* p = net + cu * stride[0] + cv * stride[1] + cw * stride[2];
                for (int h = 3; h < nc; ++h) {
                  double v = 0.0;
                  for (const auto& [off, w] : terms) v += w * p[off + h];
                  bp = std::max(bp, std::abs(v));
                }
              }
        }
        const double bound = bp * std::abs(factor) * (1.0 + 1e-12);
        const int idx[3] = {d, e, f};
        // Every ordering of (d, e, f).
        for (int x = 0; x < 3; ++x)
          for (int y = 0; y < 3; ++y)
            for (int z = 0; z < 3; ++z)
              if (x != y && y != z && x != z)
                b.p3[static_cast<std::size_t>(idx[x])][static_cast<std::size_t>(idx[y])][static_cast<std::size_t>(idx[z])] = bound;
      }
}

/// Hodograph bound: |dX/dt_d| <= (order - 1) max |P_{i+1} - P_i| / len (polynomial nets with
/// `stride` coordinates per point, xyz first).
Vec3 hodograph_bounds(const double* net, const Data::Piece& pc, int stride) {
  Vec3 out{};
  const auto& o = pc.order;
  for (int d = 0; d < 3; ++d) {
    const auto dd = static_cast<std::size_t>(d);
    if (o[dd] < 2) continue;
    const std::ptrdiff_t step = static_cast<std::ptrdiff_t>(d == 0 ? 1 : d == 1 ? o[0] : o[0] * o[1]) * stride;
    std::array<int, 3> lim = o;
    lim[dd] -= 1;
    double mx2 = 0.0;  // the largest squared norm (one root at the end: the same maximum)
    for (int c = 0; c < lim[2]; ++c)
      for (int b = 0; b < lim[1]; ++b) {
        const double* p = net + static_cast<std::ptrdiff_t>(o[0] * (b + o[1] * c)) * stride;
        for (int a = 0; a < lim[0]; ++a, p += stride) {
          const double diff[3] = {p[step] - p[0], p[step + 1] - p[1], p[step + 2] - p[2]};
          mx2 = std::max(mx2, dot3(diff, diff));
        }
      }
    // The same 1e-12 relative slack as the second-derivative bounds, for rounding.
    out[dd] = (o[dd] - 1) * std::sqrt(mx2) * pc.inv_len[dd] * (1.0 + 1e-12);
  }
  return out;
}

/// Everything the sampler's certificates need of a polynomial piece (or part of one: `pc` gives
/// the parameter box of `net`, nc = 3 + m coordinates per point).
StepBounds step_bounds_of(const double* net, const Data::Piece& pc) {
  StepBounds b = second_derivative_bounds(net, pc);
  third_partial_bounds(net, pc, b);
  b.slope = hodograph_bounds(net, pc, pc.nc);
  for (std::size_t d = 0; d < 3; ++d) b.degree[d] = pc.order[d] - 1;
  return b;
}

/// A cell's Bezier pieces, before they are built.
struct CellPieces {
  Data::Cell cell;
  /// The cell in Bezier form: its pieces are disjoint blocks of `order` points per span and
  /// direction, read in place (PieceRef) rather than copied into a spline each, as
  /// spline::bezier_pieces does (the filleted teapot: 350k pieces, four allocations each).
  spline::TensorSpline<3> bezier;
  std::array<int, 3> spans{};
  std::array<std::vector<double>, 3> breaks;  ///< the Bezier form's breakpoints
  int H = 3;  ///< geometry coordinates: 4 for a rational cell

  int pieces() const noexcept { return spans[0] * spans[1] * spans[2]; }
};

/// Piece e (u fastest) of a cell's Bezier form: bezier_pieces(s)[e] without the copy, the same
/// domain, points and weights.
struct PieceRef {
  const spline::TensorSpline<3>* b = nullptr;
  std::array<int, 3> el{}, order{};
  std::array<std::array<double, 2>, 3> dom{};

  PieceRef(const CellPieces& cp, int e) : b(&cp.bezier), order(cp.bezier.orders()) {
    for (std::size_t d = 0; d < 3; ++d) {
      el[d] = e % cp.spans[d];
      e /= cp.spans[d];
      dom[d] = {cp.breaks[d][static_cast<std::size_t>(el[d])], cp.breaks[d][static_cast<std::size_t>(el[d]) + 1]};
    }
  }
  int size() const noexcept { return order[0] * order[1] * order[2]; }
  /// The Bezier form's row of the piece's local point i (u fastest).
  int row(int i) const noexcept {
    std::array<int, 3> src{};
    for (std::size_t d = 0; d < 3; ++d) {
      src[d] = el[d] * order[d] + i % order[d];
      i /= order[d];
    }
    return b->row(src);
  }
};

/// The cell's domain, breakpoints and Bezier pieces.
CellPieces cell_pieces(const vmodel::VCell& vc) {
  const auto& s = vc.volume;
  CellPieces cp;
  for (int d = 0; d < 3; ++d) {
    const auto dd = static_cast<std::size_t>(d);
    if (s.knots(d).order() > max_order)
      throw Error("cell " + vc.name + ": order " + std::to_string(s.knots(d).order()) + " in direction " + "uvw"[d] +
                  "; expected at most " + std::to_string(max_order) + " for point location");
    for (const auto& br : s.knots(d).breakpoints()) cp.cell.breaks[dd].push_back(br.value);
    cp.cell.spans[dd] = static_cast<int>(cp.cell.breaks[dd].size()) - 1;
    cp.cell.lo[dd] = s.domain(d)[0];
    cp.cell.hi[dd] = s.domain(d)[1];
  }
  cp.bezier = spline::to_bezier_form(s);
  for (std::size_t d = 0; d < 3; ++d) {
    for (const auto& br : cp.bezier.knots(static_cast<int>(d)).breakpoints()) cp.breaks[d].push_back(br.value);
    cp.spans[d] = static_cast<int>(cp.breaks[d].size()) - 1;
  }
  cp.H = s.rational() ? 4 : 3;
  return cp;
}

/// Builds one Bezier piece: its Piece record, its net (written to `pool`, pc.net values on) and
/// its leaves (appended to `leaves`). The whole-piece StepBounds are left to first use.
/// @param piece_index  the piece's index among all pieces of the locator
/// @param H            the cell's geometry coordinates (CellPieces::H)
Data::Piece build_piece(const PieceRef& bp, int H, int cell_index, int piece_index, std::size_t net, int m,
                        const LocatorOptions& opt, double* pool, std::vector<LocatorLeaf>& leaves) {
  Data::Piece pc;
  pc.cell = cell_index;
  pc.order = bp.order;
  pc.H = H;
  pc.nc = H + m;
  pc.net = net;
  pc.k = H == 3 ? pick_kernels<3>(pc.order, pc.nc) : pick_kernels<4>(pc.order, pc.nc);
  for (int d = 0; d < 3; ++d) {
    const auto dd = static_cast<std::size_t>(d);
    pc.lo[dd] = bp.dom[dd][0];
    pc.len[dd] = bp.dom[dd][1] - bp.dom[dd][0];
    pc.inv_len[dd] = 1.0 / pc.len[dd];
  }
  const int n = bp.size();
  std::vector<double> g(static_cast<std::size_t>(n * H));
  double* all = pool + net;
  for (int i = 0; i < n; ++i) {
    const int row = bp.row(i);
    const auto q = bp.b->point(row);
    const double w = H == 4 ? bp.b->weights()[static_cast<std::size_t>(row)] : 1.0;
    for (int h = 0; h < 3; ++h) g[static_cast<std::size_t>(i * H + h)] = w * q[static_cast<std::size_t>(h)];
    if (H == 4) g[static_cast<std::size_t>(i * H + 3)] = w;
    for (int h = 0; h < H; ++h) all[i * pc.nc + h] = g[static_cast<std::size_t>(i * H + h)];
    for (int h = 0; h < m; ++h) all[i * pc.nc + H + h] = w * q[static_cast<std::size_t>(3 + h)];
  }
  pc.lipschitz = H == 4 ? Vec3{inf, inf, inf} : hodograph_bounds(g.data(), pc, H);
  std::vector<LeafBox> lv;
  const double min_diag = 100.0 * opt.tolerance;
  build_leaves(g.data(), pc.order, H, min_diag, opt.leaf_deviation, opt.fine_leaf_deviation, opt.fine_leaf_factor, opt.max_leaves_per_piece, lv);
  leaves.reserve(lv.size());
  for (const auto& [lo, hi, fl] : lv) {
    LocatorLeaf leaf;
    leaf.cell = cell_index;
    leaf.piece = piece_index;
    for (int d = 0; d < 3; ++d) {
      const auto dd = static_cast<std::size_t>(d);
      // The piece's own end knots at the ends, so leaves tile the domain without gaps.
      leaf.lo[dd] = lo[dd] <= 0.0 ? bp.dom[static_cast<std::size_t>(d)][0] : pc.lo[dd] + lo[dd] * pc.len[dd];
      leaf.hi[dd] = hi[dd] >= 1.0 ? bp.dom[static_cast<std::size_t>(d)][1] : pc.lo[dd] + hi[dd] * pc.len[dd];
    }
    leaf.box_lo = fl.box_lo;
    leaf.box_hi = fl.box_hi;
    leaf.frame_origin = fl.origin;
    leaf.frame = fl.frame;
    leaf.frame_lo = fl.frame_lo;
    leaf.frame_hi = fl.frame_hi;
    for (std::size_t k = 0; k < 3; ++k)
      leaf.frame_scale[k] = std::sqrt(fl.frame[k][0] * fl.frame[k][0] + fl.frame[k][1] * fl.frame[k][1] + fl.frame[k][2] * fl.frame[k][2]);
    leaves.push_back(leaf);
  }
  return pc;
}

/// Median-split BVH over the leaf boxes.
void build_bvh(Data& D) {
  const int n = static_cast<int>(D.leaves.size());
  D.items.resize(static_cast<std::size_t>(n));
  std::iota(D.items.begin(), D.items.end(), 0);
  D.nodes.clear();
  if (n == 0) return;
  auto centre = [&](int i, int d) {
    const auto& l = D.leaves[static_cast<std::size_t>(i)];
    return l.box_lo[static_cast<std::size_t>(d)] + l.box_hi[static_cast<std::size_t>(d)];
  };
  struct Task {
    int node, first, count;
  };
  D.nodes.push_back({});
  std::vector<Task> stack{{0, 0, n}};
  while (!stack.empty()) {
    const Task t = stack.back();
    stack.pop_back();
    Data::Node nd;
    nd.lo = {inf, inf, inf};
    nd.hi = {-inf, -inf, -inf};
    for (int k = t.first; k < t.first + t.count; ++k) {
      const auto& l = D.leaves[static_cast<std::size_t>(D.items[static_cast<std::size_t>(k)])];
      for (int d = 0; d < 3; ++d) {
        nd.lo[static_cast<std::size_t>(d)] = std::min(nd.lo[static_cast<std::size_t>(d)], l.box_lo[static_cast<std::size_t>(d)]);
        nd.hi[static_cast<std::size_t>(d)] = std::max(nd.hi[static_cast<std::size_t>(d)], l.box_hi[static_cast<std::size_t>(d)]);
      }
    }
    if (t.count <= 4) {
      nd.first = t.first;
      nd.count = t.count;
      D.nodes[static_cast<std::size_t>(t.node)] = nd;
      continue;
    }
    int axis = 0;
    for (int d = 1; d < 3; ++d)
      if (nd.hi[static_cast<std::size_t>(d)] - nd.lo[static_cast<std::size_t>(d)] >
          nd.hi[static_cast<std::size_t>(axis)] - nd.lo[static_cast<std::size_t>(axis)])
        axis = d;
    const int half = t.count / 2;
    auto b = D.items.begin() + t.first;
    std::nth_element(b, b + half, b + t.count, [&](int x, int y) {
      const double cx = centre(x, axis), cy = centre(y, axis);
      return cx < cy || (cx == cy && x < y);
    });
    nd.left = static_cast<int>(D.nodes.size());
    nd.right = nd.left + 1;
    D.nodes.push_back({});
    D.nodes.push_back({});
    D.nodes[static_cast<std::size_t>(t.node)] = nd;
    stack.push_back({nd.left, t.first, half});
    stack.push_back({nd.right, t.first + half, t.count - half});
  }
}

}  // namespace

Locator::Locator(const vmodel::VModel& model, LocatorOptions opt) : model_(&model), opt_(opt), data_(std::make_unique<Data>()) {
  if (!(std::isfinite(opt.tolerance) && opt.tolerance > 0.0))
    throw Error("locator tolerance " + std::to_string(opt.tolerance) + "; expected a positive finite length");
  if (opt_.max_newton < 1) opt_.max_newton = 1;
  Data& D = *data_;
  D.m = static_cast<int>(model.properties.size());
  const int nc = static_cast<int>(model.cells.size());
  for (int c = 0; c < nc; ++c)
    if (model.cells[static_cast<std::size_t>(c)].volume.dim() != model.dim())
      throw Error("cell " + model.cells[static_cast<std::size_t>(c)].name + ": " +
                  std::to_string(model.cells[static_cast<std::size_t>(c)].volume.dim()) +
                  " coordinates per control point; expected " + std::to_string(model.dim()) + " (xyz and the model's properties)");
  // The pieces of each cell are known from its knots (one per non-empty span triple, each with
  // the cell's orders): every piece's slots are sized up front. Cells are then extracted and
  // built in batches of consecutive cells whose Bezier pieces take at most batch_bytes (a
  // thousand-span fillet cell alone makes 100k pieces, hundreds of MB as splines), each batch's
  // cells and then its pieces in parallel, and its pieces freed before the next batch; each
  // piece writes its own slots (its Piece, its part of the pool, its leaves), concatenated in
  // order afterwards: the same locator whatever the thread count.
  constexpr double batch_bytes = 64.0 * 1024 * 1024;
  std::vector<std::size_t> first_piece(static_cast<std::size_t>(nc) + 1, 0);
  std::vector<double> cell_bytes(static_cast<std::size_t>(nc), 0.0);
  std::vector<std::size_t> nets;  // pool offset per piece
  std::size_t size = 0;
  for (int c = 0; c < nc; ++c) {
    const auto& v = model.cells[static_cast<std::size_t>(c)].volume;
    std::size_t pieces = 1, per_piece = 1;
    for (int d = 0; d < 3; ++d) {
      pieces *= v.knots(d).breakpoints().size() - 1;
      per_piece *= static_cast<std::size_t>(v.knots(d).order());
    }
    const std::size_t values = per_piece * static_cast<std::size_t>((v.rational() ? 4 : 3) + D.m);
    for (std::size_t i = 0; i < pieces; ++i) {
      nets.push_back(size);
      size += values;
    }
    first_piece[static_cast<std::size_t>(c) + 1] = first_piece[static_cast<std::size_t>(c)] + pieces;
    cell_bytes[static_cast<std::size_t>(c)] = static_cast<double>(pieces) * static_cast<double>(per_piece * static_cast<std::size_t>(v.dim())) * 8.0;
  }
  D.pool.resize(size);
  D.pieces.resize(nets.size());
  D.cells.resize(static_cast<std::size_t>(nc));
  std::vector<std::vector<LocatorLeaf>> leaves(nets.size());
  for (int c0 = 0; c0 < nc;) {
    int c1 = c0 + 1;
    for (double bytes = cell_bytes[static_cast<std::size_t>(c0)]; c1 < nc && bytes + cell_bytes[static_cast<std::size_t>(c1)] <= batch_bytes; ++c1)
      bytes += cell_bytes[static_cast<std::size_t>(c1)];
    std::vector<CellPieces> cells(static_cast<std::size_t>(c1 - c0));
    tbb::parallel_for(c0, c1, [&](int c) { cells[static_cast<std::size_t>(c - c0)] = cell_pieces(model.cells[static_cast<std::size_t>(c)]); });
    for (int c = c0; c < c1; ++c)
      if (static_cast<std::size_t>(cells[static_cast<std::size_t>(c - c0)].pieces()) != first_piece[static_cast<std::size_t>(c) + 1] - first_piece[static_cast<std::size_t>(c)])
        throw Error("cell " + model.cells[static_cast<std::size_t>(c)].name + ": internal: Bezier extraction made " +
                        std::to_string(cells[static_cast<std::size_t>(c - c0)].pieces()) + " pieces; expected one per span",
                    ErrorKind::failed);
    tbb::parallel_for(first_piece[static_cast<std::size_t>(c0)], first_piece[static_cast<std::size_t>(c1)], [&](std::size_t i) {
      const int c = static_cast<int>(std::upper_bound(first_piece.begin(), first_piece.end(), i) - first_piece.begin()) - 1;
      const auto& cp = cells[static_cast<std::size_t>(c - c0)];
      D.pieces[i] = build_piece(PieceRef(cp, static_cast<int>(i - first_piece[static_cast<std::size_t>(c)])), cp.H, c, static_cast<int>(i), nets[i], D.m, opt_,
                                D.pool.data(), leaves[i]);
    });
    for (int c = c0; c < c1; ++c) {
      auto& cell = cells[static_cast<std::size_t>(c - c0)].cell;
      cell.first_piece = static_cast<int>(first_piece[static_cast<std::size_t>(c)]);
      D.cells[static_cast<std::size_t>(c)] = std::move(cell);
    }
    c0 = c1;
  }
  std::size_t total = 0;
  for (const auto& l : leaves) total += l.size();
  D.leaves.reserve(total);
  for (const auto& l : leaves) D.leaves.insert(D.leaves.end(), l.begin(), l.end());
  build_bvh(D);
  D.bounds_once = std::make_unique<Once[]>(D.pieces.size());
  // Booleans' trimming: one locator per condition, built recursively (their cells may be
  // trimmed too).
  D.trims.resize(static_cast<std::size_t>(nc));
  for (int c = 0; c < nc; ++c) {
    const auto& cell = model.cells[static_cast<std::size_t>(c)];
    if (cell.plain()) continue;
    auto trim = std::make_unique<Data::Trim>();
    trim->blend = cell.blend;
    const auto sub = [&](std::vector<vmodel::VCell> cells) {
      auto s = std::make_unique<Data::Sub>();
      s->model.units = model.units;
      s->model.properties = model.properties;
      s->model.cells = std::move(cells);
      s->loc = std::make_unique<Locator>(s->model, opt_);
      return s;
    };
    for (const auto& w : cell.within) trim->within.push_back(sub({w}));
    for (const auto& solid : cell.without) trim->without.push_back(sub(solid));
    if (cell.blend == vmodel::BlendRule::distance) {
      // Without one boundary per value the distances are undefined: the plain mean then.
      if (cell.boundaries.size() != 1 + cell.within.size()) {
        trim->blend = vmodel::BlendRule::mean;
      } else {
        trim->power = cell.blend_power;
        for (const auto& list : cell.boundaries) {
          std::vector<geom::SurfaceDistance> d;
          for (const auto& f : list) d.emplace_back(f);
          trim->boundaries.push_back(std::move(d));
        }
      }
    }
    D.trims[static_cast<std::size_t>(c)] = std::move(trim);
    D.any_trim = true;
  }
}

bool Locator::trimmed(int cell) const noexcept { return data_->trims[static_cast<std::size_t>(cell)] != nullptr; }
bool Locator::has_trims() const noexcept { return data_->any_trim; }

bool Locator::admits(int cell, const Vec3& p, double* props) const {
  const auto& trim = data_->trims[static_cast<std::size_t>(cell)];
  if (!trim) return true;
  for (const auto& o : trim->without)
    if (o->loc->locate(p).inside) return false;
  const int m = data_->m;
  const bool blend = props && m > 0 && trim->blend != vmodel::BlendRule::first;
  // The values to combine: the cell's own (props on entry), then each within cell's at p, with
  // its own blend applied; each within cell must hold p.
  std::vector<double> values;
  if (blend) values.assign(props, props + m);
  for (const auto& w : trim->within) {
    const auto r = w->loc->locate(p);
    if (!r.inside) return false;
    if (!blend) continue;
    const std::size_t at = values.size();
    values.resize(at + static_cast<std::size_t>(m));
    double x[3];
    w->loc->eval(r.cell, r.uvw, x, values.data() + at);
    w->loc->admits(r.cell, p, values.data() + at);
  }
  if (!blend) return true;
  const std::size_t n = values.size() / static_cast<std::size_t>(m);
  // Weights: 1 for the sum and the mean; Massarwi & Elber 2016, Eq. 2's d_i^k for the distance blend, d_i the
  // distance to input i's boundary (on every input's boundary at once, Eq. 2's singular points,
  // the plain mean).
  std::vector<double> w(n, 1.0);
  if (trim->blend == vmodel::BlendRule::distance) {
    double wsum = 0.0;
    for (std::size_t i = 0; i < n; ++i) wsum += w[i] = std::pow(geom::distance(trim->boundaries[i], p), trim->power);
    if (!(wsum > 0)) std::fill(w.begin(), w.end(), 1.0);
  }
  double wsum = 0.0;
  for (double x : w) wsum += x;
  for (int h = 0; h < m; ++h) {
    double acc = 0.0;
    for (std::size_t i = 0; i < n; ++i) acc += w[i] * values[i * static_cast<std::size_t>(m) + static_cast<std::size_t>(h)];
    props[h] = trim->blend == vmodel::BlendRule::sum_clip ? std::clamp(acc, 0.0, 1.0) : acc / wsum;
  }
  return true;
}

Locator::~Locator() = default;
Locator::Locator(Locator&&) noexcept = default;
Locator& Locator::operator=(Locator&&) noexcept = default;

const vmodel::VModel& Locator::model() const noexcept { return *model_; }
const LocatorOptions& Locator::options() const noexcept { return opt_; }
std::span<const LocatorLeaf> Locator::leaves() const noexcept { return data_->leaves; }

std::array<Vec3, 2> Locator::domain(int cell) const noexcept {
  const auto& c = data_->cells[static_cast<std::size_t>(cell)];
  return {c.lo, c.hi};
}

void Locator::query(const Vec3& lo, const Vec3& hi, double pad, std::vector<int>& out) const {
  out.clear();
  const Data& D = *data_;
  if (D.nodes.empty()) return;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  auto overlaps = [&](const Vec3& blo, const Vec3& bhi) {
    for (int d = 0; d < 3; ++d)
      if (bhi[static_cast<std::size_t>(d)] + pad < lo[static_cast<std::size_t>(d)] ||
          blo[static_cast<std::size_t>(d)] - pad > hi[static_cast<std::size_t>(d)])
        return false;
    return true;
  };
  while (top > 0) {
    const auto& nd = D.nodes[static_cast<std::size_t>(stack[--top])];
    if (!overlaps(nd.lo, nd.hi)) continue;
    if (nd.left < 0) {
      for (int k = nd.first; k < nd.first + nd.count; ++k) {
        const int li = D.items[static_cast<std::size_t>(k)];
        const auto& l = D.leaves[static_cast<std::size_t>(li)];
        if (overlaps(l.box_lo, l.box_hi)) out.push_back(li);
      }
      continue;
    }
    stack[top++] = nd.left;
    stack[top++] = nd.right;
  }
  std::sort(out.begin(), out.end());
}

void Locator::eval(int cell, const Vec3& uvw, double* xyz, double* props) const {
  const auto& pc = data_->piece_at(cell, uvw);
  Scratch buf(pc.nc);
  data_->eval_all(pc, uvw, buf.data(), xyz, props);
}

void Locator::eval_properties(int cell, const Vec3& uvw, float* props) const {
  const auto& pc = data_->piece_at(cell, uvw);
  Scratch buf(pc.nc);
  double x[3];
  data_->eval_all(pc, uvw, buf.data(), x, props);
}

bool Locator::check(int cell, const Vec3& p, const Vec3& uvw, float* props, Vec3* residual) const {
  const Data& D = *data_;
  const auto& pc = D.piece_at(cell, uvw);
  double x[3];
  if (pc.nc <= 64) {
    double buf[64];
    D.eval_all(pc, uvw, buf, x, props);
  } else {
    std::vector<double> buf(static_cast<std::size_t>(pc.nc));
    D.eval_all(pc, uvw, buf.data(), x, props);
  }
  const Vec3 r{p[0] - x[0], p[1] - x[1], p[2] - x[2]};
  if (residual) *residual = r;
  return r[0] * r[0] + r[1] * r[1] + r[2] * r[2] < opt_.tolerance * opt_.tolerance;
}

bool Locator::expand(int cell, const Vec3& t, Expansion& out) const {
  const Data& D = *data_;
  const auto& pc = D.piece_at(cell, t);
  if (!pc.k.all_first || D.m > Expansion::max_props) return false;
  const auto dom = domain(cell);
  Vec3 tc;
  for (std::size_t d = 0; d < 3; ++d) tc[d] = std::clamp(t[d], dom[0][d], dom[1][d]);
  double s[3], f[4 * 10];
  Data::local(pc, tc, s);
  pc.k.all_first(D.pool.data() + pc.net, pc.nc, pc.order, s, f);
  const int nc = pc.nc;
  out.piece = static_cast<int>(&pc - D.pieces.data());
  out.t = tc;
  for (std::size_t h = 0; h < 3; ++h) {
    out.x[h] = f[h];
    for (std::size_t d = 0; d < 3; ++d) out.jac[d][h] = f[static_cast<std::size_t>(nc) * (d + 1) + h] * pc.inv_len[d];
  }
  for (int h = 0; h < D.m; ++h) {
    const auto uh = static_cast<std::size_t>(h);
    out.props[uh] = f[3 + uh];
    for (std::size_t d = 0; d < 3; ++d) out.grad[uh][d] = f[static_cast<std::size_t>(nc) * (d + 1) + 3 + uh] * pc.inv_len[d];
  }
  return true;
}

void Locator::piece_properties(int piece, const Vec3* t, int n, double* out) const {
  const Data& D = *data_;
  const auto& pc = D.pieces[static_cast<std::size_t>(piece)];
  if (D.m == 0 || n <= 0) return;
  if (pc.H != 3) {  // rational: not one polynomial; each point evaluated (clamped) instead
    Scratch buf(pc.nc);
    double x[3];
    for (int j = 0; j < n; ++j) D.eval_all(pc, t[j], buf.data(), x, out + static_cast<std::size_t>(j) * static_cast<std::size_t>(D.m));
    return;
  }
  const Props8 kernel = pc.k.props, kernel4 = pc.k.props4;
  const double* net = D.pool.data() + pc.net;
  const auto um = static_cast<std::size_t>(D.m);
  double s[3][8], buf[8 * Expansion::max_props];
  std::vector<double> heap;
  double* vals = buf;
  if (D.m > Expansion::max_props) {
    heap.resize(8 * um);
    vals = heap.data();
  }
  for (int j0 = 0; j0 < n; j0 += 8) {
    const int k = std::min(8, n - j0);
    for (int l = 0; l < 8; ++l) {
      const Vec3& p = t[j0 + std::min(l, k - 1)];  // spare lanes repeat the last point
      for (std::size_t d = 0; d < 3; ++d) s[d][l] = (p[d] - pc.lo[d]) * pc.inv_len[d];
    }
    (k <= 4 && kernel4 ? kernel4 : kernel)(net, pc.nc, pc.H, D.m, pc.order, s, vals);  // a short chunk: half the lanes
    std::copy_n(vals, static_cast<std::size_t>(k) * um, out + static_cast<std::size_t>(j0) * um);
  }
}

const StepBounds& Locator::step_bounds(int piece) const noexcept {
  const auto& pc = data_->pieces[static_cast<std::size_t>(piece)];
  if (!pc.k.all_first) return pc.bounds;  // not valid
  data_->bounds_once[static_cast<std::size_t>(piece)]([&] { pc.bounds = step_bounds_of(data_->pool.data() + pc.net, pc); });
  return pc.bounds;
}

namespace {
/// A converged answer, with one more Newton step (not evaluated) as the warm start for neighbours:
/// the answer itself is only within the tolerance, and extrapolating from such answers would
/// amplify that error; the extra step brings it to about the square of the residual.
NewtonResult converged(const Vec3& t, const double J[3][3], const double* r, double rn, const Vec3& lo, const Vec3& hi) {
  NewtonResult res{NewtonStatus::converged, t, rn, t, {}};
  for (std::size_t d = 0; d < 3; ++d) res.jacobian[d] = {J[d][0], J[d][1], J[d][2]};
  double step[3];
  solve3(J, r, step);
  for (std::size_t d = 0; d < 3; ++d) res.polished[d] = std::clamp(t[d] + step[d], lo[d], hi[d]);
  return res;
}
}  // namespace

NewtonResult Locator::newton(int cell, const Vec3& p, const Vec3& start, const Vec3& lo, const Vec3& hi, int max_iter) const {
  const Data& D = *data_;
  const double tol = opt_.tolerance;
  if (max_iter <= 0) max_iter = opt_.max_newton;
  Vec3 t;
  for (int d = 0; d < 3; ++d) t[static_cast<std::size_t>(d)] = std::clamp(start[static_cast<std::size_t>(d)], lo[static_cast<std::size_t>(d)], hi[static_cast<std::size_t>(d)]);
  double X[3], J[3][3], r[3];
  D.eval_geom(D.piece_at(cell, t), t, X, J);
  for (int h = 0; h < 3; ++h) r[h] = p[static_cast<std::size_t>(h)] - X[h];
  double rn = norm3(r);
  NewtonResult res;
  for (int it = 0; it < max_iter; ++it) {
    if (rn < tol) return converged(t, J, r, rn, lo, hi);
    if (!std::isfinite(rn)) break;
    // Projected Newton: freeze coordinates at a bound whose step points outwards.
    double step[3];
    bool free[3] = {true, true, true};
    solve3(J, r, step);
    bool pinned = false;
    for (int pass = 0; pass < 3; ++pass) {
      bool changed = false;
      for (int d = 0; d < 3; ++d) {
        const auto dd = static_cast<std::size_t>(d);
        if (free[d] && ((t[dd] <= lo[dd] && step[d] < 0.0) || (t[dd] >= hi[dd] && step[d] > 0.0))) {
          free[d] = false;
          changed = pinned = true;
        }
      }
      if (!changed) break;
      solve_free(J, r, free, step);
    }
    if (pinned) {
      double pred[3];
      for (int h = 0; h < 3; ++h) pred[h] = J[0][h] * step[0] + J[1][h] * step[1] + J[2][h] * step[2];
      double rest[3] = {r[0] - pred[0], r[1] - pred[1], r[2] - pred[2]};
      const double e = norm3(rest), moved = norm3(pred);
      // Stationary on the box boundary, pulled outwards, and the first-order residual is real.
      if (e > tol && moved <= std::max(0.5 * tol, 0.05 * e)) return {NewtonStatus::outside, t, rn, t, {}};
    }
    // Damped step: halve until the residual decreases.
    double lambda = 1.0;
    bool accepted = false;
    for (int ls = 0; ls < 8; ++ls, lambda *= 0.5) {
      Vec3 tn;
      for (int d = 0; d < 3; ++d)
        tn[static_cast<std::size_t>(d)] = std::clamp(t[static_cast<std::size_t>(d)] + lambda * step[d], lo[static_cast<std::size_t>(d)], hi[static_cast<std::size_t>(d)]);
      double Xn[3], Jn[3][3], rnv[3];
      D.eval_geom(D.piece_at(cell, tn), tn, Xn, Jn);
      for (int h = 0; h < 3; ++h) rnv[h] = p[static_cast<std::size_t>(h)] - Xn[h];
      const double rnn = norm3(rnv);
      if (rnn < rn || rnn < tol) {
        t = tn;
        std::copy(rnv, rnv + 3, r);
        std::copy(&Jn[0][0], &Jn[0][0] + 9, &J[0][0]);
        rn = rnn;
        accepted = true;
        break;
      }
    }
    if (!accepted) {
      // No descent along the Newton direction: stuck. Pinned on the boundary means outside.
      if (pinned && rn > tol) return {NewtonStatus::outside, t, rn, t, {}};
      break;
    }
  }
  if (rn < tol) return converged(t, J, r, rn, lo, hi);
  return {NewtonStatus::failed, t, rn, t, {}};
}

namespace {
/// Newton in every 1/3 x 1/3 x 1/3 part of [lo, hi]; recursion `depth` levels deep on parts that fail.
NewtonResult subdivide(const Locator& L, const Data& D, int cell, const Vec3& p, const Vec3& lo, const Vec3& hi, int depth) {
  NewtonResult best;
  best.residual = inf;
  bool failed = false;
  const double tol = L.options().tolerance;
  for (int k = 0; k < 27; ++k) {
    const int idx[3] = {k % 3, (k / 3) % 3, k / 9};
    Vec3 a, b, c;
    for (int d = 0; d < 3; ++d) {
      const auto dd = static_cast<std::size_t>(d);
      const double w = (hi[dd] - lo[dd]) / 3.0;
      a[dd] = lo[dd] + idx[d] * w;
      b[dd] = idx[d] == 2 ? hi[dd] : lo[dd] + (idx[d] + 1) * w;
      c[dd] = 0.5 * (a[dd] + b[dd]);
    }
    // Skip parts whose image provably misses p (hodograph bound; polynomial pieces).
    const auto& pc = D.piece_at(cell, c);
    double X[3];
    D.eval_geom(pc, c, X, nullptr);
    const double dist = std::sqrt((X[0] - p[0]) * (X[0] - p[0]) + (X[1] - p[1]) * (X[1] - p[1]) + (X[2] - p[2]) * (X[2] - p[2]));
    double reach = tol;
    for (int d = 0; d < 3; ++d) reach += pc.lipschitz[static_cast<std::size_t>(d)] * 0.5 * (b[static_cast<std::size_t>(d)] - a[static_cast<std::size_t>(d)]);
    if (dist > reach) continue;
    NewtonResult r = L.newton(cell, p, c, a, b);
    if (r.status == NewtonStatus::failed && depth > 1) r = subdivide(L, D, cell, p, a, b, depth - 1);
    if (r.status == NewtonStatus::converged) return r;
    if (r.status == NewtonStatus::failed) failed = true;
    if (r.residual < best.residual) best = r;
  }
  best.status = failed ? NewtonStatus::failed : NewtonStatus::outside;
  if (!std::isfinite(best.residual)) best.uvw = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])};
  return best;
}
}  // namespace

NewtonResult Locator::solve_in_leaf(int leaf, const Vec3& p, const Vec3* start) const {
  const auto& l = data_->leaves[static_cast<std::size_t>(leaf)];
  const Vec3 c = {0.5 * (l.lo[0] + l.hi[0]), 0.5 * (l.lo[1] + l.hi[1]), 0.5 * (l.lo[2] + l.hi[2])};
  NewtonResult r = newton(l.cell, p, start ? *start : c, l.lo, l.hi);
  if (r.status != NewtonStatus::failed) return r;
  if (start) {  // a warm start may have led astray: try the centre before subdividing
    r = newton(l.cell, p, c, l.lo, l.hi);
    if (r.status != NewtonStatus::failed) return r;
  }
  // Three levels (27, then 27 per failing part): next to a fillet's degenerate rail (a face
  // collapsed onto a curve, singular Jacobian) one level left the filleted teapot's slice with a
  // voxel neither placed nor excluded (tests/data/teapot_rail.json); the deeper levels run only
  // on parts whose Newton fails, so they cost nothing elsewhere.
  NewtonResult s = subdivide(*this, *data_, l.cell, p, l.lo, l.hi, 3);
  return s;
}

LocateResult Locator::locate(const Vec3& p, const LocateResult* hint) const {
  if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))) return {false, -1, {}, false};
  std::vector<int> cand;
  query(p, p, opt_.tolerance, cand);
  LocateResult out;
  const double guess = 500.0 * opt_.tolerance;
  std::size_t k = 0;
  while (k < cand.size()) {
    const int cell = data_->leaves[static_cast<std::size_t>(cand[k])].cell;
    std::size_t e = k;
    while (e < cand.size() && data_->leaves[static_cast<std::size_t>(cand[e])].cell == cell) ++e;
    if (hint && hint->inside && hint->cell == cell) {
      const auto dom = domain(cell);
      const auto r = newton(cell, p, hint->uvw, dom[0], dom[1]);
      if (r.status == NewtonStatus::converged) {
        if (admits(cell, p)) return {true, cell, r.uvw, out.converged};
        k = e;  // inside the trivariate but trimmed away: the next cell
        continue;
      }
    }
    NewtonResult best;
    best.residual = inf;
    bool failed = false;
    for (std::size_t i = k; i < e; ++i) {
      if (!data_->leaves[static_cast<std::size_t>(cand[i])].may_contain(p, opt_.tolerance)) continue;
      const auto r = solve_in_leaf(cand[i], p);
      if (r.status == NewtonStatus::converged) {
        if (admits(cell, p)) return {true, cell, r.uvw, out.converged};
        failed = false;
        break;
      }
      if (r.status == NewtonStatus::failed) {
        failed = true;
        if (r.residual < best.residual) best = r;
      }
    }
    if (failed) {
      out.converged = false;
      if (best.residual < guess && admits(cell, p)) return {true, cell, best.uvw, false};
    }
    k = e;
  }
  return out;
}

std::array<Vec3, 2> model_bounds(const vmodel::VModel& model) {
  if (model.cells.empty()) throw Error("the model has no cells; expected at least one volumetric cell to slice");
  // Cells in parallel (a thousand-span cell's Bezier form takes a while), combined in cell order.
  std::vector<std::array<std::vector<double>, 2>> boxes(model.cells.size());
  tbb::parallel_for(std::size_t{0}, boxes.size(), [&](std::size_t c) { boxes[c] = spline::bounding_box(model.cells[c].volume, 3); });
  std::array<Vec3, 2> b{Vec3{inf, inf, inf}, Vec3{-inf, -inf, -inf}};
  for (const auto& bb : boxes) {
    for (std::size_t d = 0; d < 3; ++d) {
      b[0][d] = std::min(b[0][d], bb[0][d]);
      b[1][d] = std::max(b[1][d], bb[1][d]);
    }
  }
  return b;
}

double model_diagonal(const vmodel::VModel& model) {
  const auto b = model_bounds(model);
  return std::max(std::numeric_limits<double>::min(), std::hypot(b[1][0] - b[0][0], b[1][1] - b[0][1], b[1][2] - b[0][2]));
}

}  // namespace trivox::slice
