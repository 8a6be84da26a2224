// A Bezier piece subdivided into nearly affine leaves (leaves.hpp; the locator's conservative
// regions, locator.hpp): de Casteljau halves of the net, the least-squares affine fit of its
// control points against their Greville abscissae and the largest deviation from it, and the
// frame of the fit. Cost per split: one de Casteljau triangle (O(o^3 H)) and one or two affine
// fits (O(o^3)) per direction tried; the frames only for the leaves.
#include "leaves.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace trivox::slice::detail {

namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

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

}  // namespace

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

}  // namespace trivox::slice::detail
