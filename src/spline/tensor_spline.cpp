#include "trivox/spline/tensor_spline.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "trivox/error.hpp"

namespace trivox::spline {

// ---------------------------------------------------------------------------------------------
// Multi-indices of partial derivatives

namespace {

template <int P>
std::vector<std::array<int, P>> make_multi_indices(int max_order) {
  std::vector<std::array<int, P>> out;
  for (int total = 0; total <= max_order; ++total) {
    // Lexicographic with the first direction highest: enumerate alpha_0 from total down.
    std::array<int, P> a{};
    auto rec = [&](auto&& self, int d, int left) -> void {
      if (d == P - 1) {
        a[static_cast<std::size_t>(d)] = left;
        out.push_back(a);
        return;
      }
      for (int k = left; k >= 0; --k) {
        a[static_cast<std::size_t>(d)] = k;
        self(self, d + 1, left - k);
      }
    };
    rec(rec, 0, total);
  }
  return out;
}

template <int P>
const std::vector<std::array<int, P>>& all_multi_indices() {
  static const auto table = make_multi_indices<P>(max_derivative_order);
  return table;
}

}  // namespace

template <int P>
std::span<const std::array<int, P>> derivative_multi_indices(int max_order) {
  const auto& t = all_multi_indices<P>();
  return {t.data(), static_cast<std::size_t>(derivative_count(P, std::clamp(max_order, 0, max_derivative_order)))};
}

template <int P>
int derivative_slot(const std::array<int, P>& alpha) {
  const auto& t = all_multi_indices<P>();
  for (std::size_t i = 0; i < t.size(); ++i)
    if (t[i] == alpha) return static_cast<int>(i);
  return -1;
}

// ---------------------------------------------------------------------------------------------
// Construction and indexing

template <int P>
TensorSpline<P>::TensorSpline(std::array<KnotVector, P> knots, int dim, std::vector<double> points,
                              std::vector<double> weights)
    : knots_(std::move(knots)), dim_(dim), points_(std::move(points)), weights_(std::move(weights)) {
  for (int d = 0; d < P; ++d)
    if (knots_[static_cast<std::size_t>(d)].order() < 1)
      throw Error("knot vector " + std::to_string(d) + " is empty; expected a knot vector per direction");
  if (dim_ < 1) throw Error(std::to_string(dim_) + " coordinates per control point; expected at least 1");
  const std::size_t n = static_cast<std::size_t>(size());
  if (points_.size() != n * static_cast<std::size_t>(dim_))
    throw Error(std::to_string(points_.size()) + " control point values; expected " + std::to_string(n) +
                " control points x " + std::to_string(dim_) + " coordinates = " +
                std::to_string(n * static_cast<std::size_t>(dim_)));
  for (std::size_t i = 0; i < points_.size(); ++i)
    if (!std::isfinite(points_[i]))
      throw Error("control point " + std::to_string(i / static_cast<std::size_t>(dim_)) + " coordinate " +
                  std::to_string(i % static_cast<std::size_t>(dim_)) + " is not finite; expected a finite number");
  if (!weights_.empty()) {
    if (weights_.size() != n)
      throw Error(std::to_string(weights_.size()) + " weights; expected one per control point (" +
                  std::to_string(n) + ")");
    for (std::size_t i = 0; i < n; ++i)
      if (!(std::isfinite(weights_[i]) && weights_[i] > 0.0))
        throw Error("weight " + std::to_string(i) + " is " + std::to_string(weights_[i]) +
                    "; expected a positive finite number");
  }
}

template <int P>
typename TensorSpline<P>::Index TensorSpline<P>::counts() const noexcept {
  Index c{};
  for (int d = 0; d < P; ++d) c[static_cast<std::size_t>(d)] = count(d);
  return c;
}

template <int P>
typename TensorSpline<P>::Index TensorSpline<P>::orders() const noexcept {
  Index c{};
  for (int d = 0; d < P; ++d) c[static_cast<std::size_t>(d)] = knots(d).order();
  return c;
}

template <int P>
int TensorSpline<P>::size() const noexcept {
  int n = 1;
  for (int d = 0; d < P; ++d) n *= count(d);
  return n;
}

template <int P>
int TensorSpline<P>::row(const Index& i) const noexcept {
  int r = 0;
  for (int d = P - 1; d >= 0; --d) r = r * count(d) + i[static_cast<std::size_t>(d)];
  return r;
}

template <int P>
typename TensorSpline<P>::Index TensorSpline<P>::multi_index(int r) const noexcept {
  Index i{};
  for (int d = 0; d < P; ++d) {
    i[static_cast<std::size_t>(d)] = r % count(d);
    r /= count(d);
  }
  return i;
}

template <int P>
bool TensorSpline<P>::contains(const Params& t) const noexcept {
  for (int d = 0; d < P; ++d)
    if (!knots(d).contains(t[static_cast<std::size_t>(d)])) return false;
  return true;
}

// ---------------------------------------------------------------------------------------------
// Evaluation
//
// Curves and surfaces run through the trivariate loops with unit extents in the missing
// directions, so the contraction is written once.

namespace {

constexpr int kMaxOrderStack = 16;

struct DirBasis {
  int first = 0;   // index of the first active control point
  int order = 1;
  int stride = 0;  // control points between neighbours in this direction
  int nder = 0;
  // (nder+1) x order values
  double N[(max_derivative_order + 1) * kMaxOrderStack] = {1.0};
  std::vector<double> heap;
  const double* row(int k) const { return (heap.empty() ? N : heap.data()) + k * order; }
};

template <int P>
void setup_basis(const TensorSpline<P>& s, const std::array<double, P>& t, int max_order, DirBasis (&b)[3]) {
  int stride = 1;
  for (int d = 0; d < 3; ++d) {
    DirBasis& db = b[d];
    if (d >= P) {
      db.first = 0;
      db.order = 1;
      db.stride = 0;
      db.nder = max_order;
      for (int k = 0; k <= max_order; ++k) db.N[k] = (k == 0) ? 1.0 : 0.0;
      continue;
    }
    const KnotVector& kv = s.knots(d);
    const double raw = t[static_cast<std::size_t>(d)];
    const double td = std::isnan(raw) ? kv.front() : std::clamp(raw, kv.front(), kv.back());
    const int span = kv.find_span(td);
    db.order = kv.order();
    db.first = span - kv.order() + 1;
    db.stride = stride;
    db.nder = max_order;
    double* out = db.N;
    if (db.order > kMaxOrderStack) {
      db.heap.resize(static_cast<std::size_t>((max_order + 1) * db.order));
      out = db.heap.data();
    }
    if (max_order == 0)
      kv.basis(span, td, out);
    else
      kv.basis_derivatives(span, td, max_order, out);
    stride *= kv.size();
  }
}

/// A[du][dv][dw][h] = sum over the active box of N_u^(du) N_v^(dv) N_w^(dw) Q_h, where Q is the
/// control point (homogeneous when rational). `H` is dim (+1 when rational).
void contract(const double* pts, const double* w, int dim, const DirBasis (&b)[3], int nd, double* A) {
  const int H = dim + (w ? 1 : 0);
  const int n1 = nd + 1;
  const std::size_t total = static_cast<std::size_t>(n1 * n1 * n1 * H);
  std::fill(A, A + total, 0.0);
  // Scratch rows on the stack for up to 64 coordinates; the heap beyond.
  double stack[(max_derivative_order + 1) * (max_derivative_order + 2) * 64];
  std::vector<double> heap;
  double* tu = stack;
  if (static_cast<std::size_t>(n1 * (n1 + 1) * H) > std::size(stack)) {
    heap.resize(static_cast<std::size_t>(n1 * (n1 + 1) * H));
    tu = heap.data();
  }
  double* tv = tu + n1 * H;
  for (int c = 0; c < b[2].order; ++c) {
    std::fill(tv, tv + n1 * n1 * H, 0.0);
    for (int bb = 0; bb < b[1].order; ++bb) {
      std::fill(tu, tu + n1 * H, 0.0);
      const int base = (b[0].first) * b[0].stride + (b[1].first + bb) * b[1].stride + (b[2].first + c) * b[2].stride;
      for (int a = 0; a < b[0].order; ++a) {
        const int r = base + a * b[0].stride;
        const double* q = pts + static_cast<std::ptrdiff_t>(r) * dim;
        const double wr = w ? w[r] : 1.0;
        for (int du = 0; du <= nd; ++du) {
          const double coef = b[0].row(du)[a] * wr;
          double* o = tu + du * H;
          for (int h = 0; h < dim; ++h) o[h] += coef * q[h];
          if (w) o[dim] += coef;
        }
      }
      for (int dv = 0; dv <= nd; ++dv) {
        const double nv = b[1].row(dv)[bb];
        if (nv == 0.0) continue;
        for (int du = 0; du <= nd; ++du)
          for (int h = 0; h < H; ++h) tv[(dv * n1 + du) * H + h] += nv * tu[du * H + h];
      }
    }
    for (int dw = 0; dw <= nd; ++dw) {
      const double nw = b[2].row(dw)[c];
      if (nw == 0.0) continue;
      for (int dv = 0; dv <= nd; ++dv)
        for (int du = 0; du <= nd; ++du)
          for (int h = 0; h < H; ++h)
            A[((dw * n1 + dv) * n1 + du) * H + h] += nw * tv[(dv * n1 + du) * H + h];
    }
  }
}

/// The fast path for polynomial splines, position or position with first partials, orders up to
/// 16 and up to 64 coordinates: flat basis rows and a contraction unrolled over the coordinate
/// count H when it is a compile-time constant (the common 1..8).
struct FastBasis {
  int first = 0, order = 1, stride = 0;
  double N[2 * kMaxOrderStack];  // row 0 values, row 1 first derivatives (length `order` each)
};

template <int OU, int OV, int OW, int H>
void fast_contract(const double* pts, int dim, const FastBasis (&b)[3], bool d1, double* out) {
  // Orders > 0: that direction's order (loops unroll; a surface's third direction has order 1);
  // 0: the order from b.
  constexpr int cap = H ? H : 64;
  const int D = H ? H : dim;
  const int ou = OU ? OU : b[0].order, ov = OV ? OV : b[1].order, ow = OW ? OW : b[2].order;
  double val[cap], du[cap], dv[cap], dw[cap];
  for (int h = 0; h < D; ++h) val[h] = du[h] = dv[h] = dw[h] = 0.0;
  const double *Nu = b[0].N, *Nv = b[1].N, *Nw = b[2].N;
  const double *Du = Nu + ou, *Dv = Nv + ov, *Dw = Nw + ow;
  const std::ptrdiff_t su = b[0].stride * D;
  for (int c = 0; c < ow; ++c) {
    for (int bb = 0; bb < ov; ++bb) {
      const double* row = pts + static_cast<std::ptrdiff_t>(b[0].first * b[0].stride + (b[1].first + bb) * b[1].stride +
                                                              (b[2].first + c) * b[2].stride) * D;
      const double vw = Nv[bb] * Nw[c];
      if (!d1) {
        for (int a = 0; a < ou; ++a) {
          const double* q = row + a * su;
          const double coef = Nu[a] * vw;
          for (int h = 0; h < D; ++h) val[h] += coef * q[h];
        }
        continue;
      }
      double t0[cap], t1[cap];
      for (int h = 0; h < D; ++h) t0[h] = t1[h] = 0.0;
      for (int a = 0; a < ou; ++a) {
        const double* q = row + a * su;
        const double n0 = Nu[a], n1 = Du[a];
        for (int h = 0; h < D; ++h) {
          t0[h] += n0 * q[h];
          t1[h] += n1 * q[h];
        }
      }
      const double dvw = Dv[bb] * Nw[c], vdw = Nv[bb] * Dw[c];
      for (int h = 0; h < D; ++h) {
        val[h] += vw * t0[h];
        du[h] += vw * t1[h];
        dv[h] += dvw * t0[h];
        dw[h] += vdw * t0[h];
      }
    }
  }
  for (int h = 0; h < D; ++h) out[h] = val[h];
  if (!d1) return;
  // Only the partials of existing directions are written (those with a stride).
  double* o = out + D;
  const double* parts[3] = {du, dv, dw};
  for (int d = 0; d < 3; ++d) {
    if (b[d].stride == 0) continue;
    for (int h = 0; h < D; ++h) o[h] = parts[d][h];
    o += D;
  }
}

template <int OU, int OV, int OW>
void fast_contract_dim(const double* pts, int dim, const FastBasis (&b)[3], bool d1, double* out) {
  switch (dim) {
    case 1: return fast_contract<OU, OV, OW, 1>(pts, 1, b, d1, out);
    case 2: return fast_contract<OU, OV, OW, 2>(pts, 2, b, d1, out);
    case 3: return fast_contract<OU, OV, OW, 3>(pts, 3, b, d1, out);
    case 4: return fast_contract<OU, OV, OW, 4>(pts, 4, b, d1, out);
    case 5: return fast_contract<OU, OV, OW, 5>(pts, 5, b, d1, out);
    case 6: return fast_contract<OU, OV, OW, 6>(pts, 6, b, d1, out);
    case 7: return fast_contract<OU, OV, OW, 7>(pts, 7, b, d1, out);
    case 8: return fast_contract<OU, OV, OW, 8>(pts, 8, b, d1, out);
    default: return fast_contract<OU, OV, OW, 0>(pts, dim, b, d1, out);
  }
}

template <int P>
bool fast_eval(const TensorSpline<P>& s, const std::array<double, P>& t, int max_order, double* out) {
  if (s.rational() || max_order > 1 || s.dim() > 64) return false;
  FastBasis b[3];
  int stride = 1;
  for (int d = 0; d < 3; ++d) {
    FastBasis& fb = b[d];
    if (d >= P) {
      fb.first = 0;
      fb.order = 1;
      fb.stride = 0;
      fb.N[0] = 1.0;
      fb.N[1] = 0.0;
      continue;
    }
    const KnotVector& kv = s.knots(d);
    if (kv.order() > kMaxOrderStack) return false;
    const double raw = t[static_cast<std::size_t>(d)];
    const double td = std::isnan(raw) ? kv.front() : std::clamp(raw, kv.front(), kv.back());
    const int span = kv.find_span(td);
    fb.order = kv.order();
    fb.first = span - fb.order + 1;
    fb.stride = stride;
    if (max_order == 0)
      kv.basis(span, td, fb.N);
    else
      kv.basis_derivatives(span, td, 1, fb.N);
    stride *= kv.size();
  }
  const double* pts = s.points().data();
  const bool d1 = max_order == 1;
  // Equal orders 2..4 in every direction of a trivariate or a surface (whose third direction
  // has order 1) unroll; the same operations in the same order as the runtime-order loops.
  const int o = b[0].order;
  const bool uniform = b[1].order == o && (P == 3 ? b[2].order == o : P == 2);
  const int key = uniform ? (P == 3 ? o : 10 + o) : 0;
  switch (key) {
    case 2: fast_contract_dim<2, 2, 2>(pts, s.dim(), b, d1, out); break;
    case 3: fast_contract_dim<3, 3, 3>(pts, s.dim(), b, d1, out); break;
    case 4: fast_contract_dim<4, 4, 4>(pts, s.dim(), b, d1, out); break;
    case 12: fast_contract_dim<2, 2, 1>(pts, s.dim(), b, d1, out); break;
    case 13: fast_contract_dim<3, 3, 1>(pts, s.dim(), b, d1, out); break;
    case 14: fast_contract_dim<4, 4, 1>(pts, s.dim(), b, d1, out); break;
    default: fast_contract_dim<0, 0, 0>(pts, s.dim(), b, d1, out); break;
  }
  return true;
}

int binom(int n, int k) {
  int r = 1;
  for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return r;
}

}  // namespace

template <int P>
void TensorSpline<P>::eval(const Params& t, double* out) const noexcept {
  eval_derivatives(t, 0, out);
}

template <int P>
std::vector<double> TensorSpline<P>::eval(const Params& t) const {
  std::vector<double> out(static_cast<std::size_t>(dim_));
  eval(t, out.data());
  return out;
}

template <int P>
void TensorSpline<P>::eval_derivatives(const Params& t, int max_order, double* out) const noexcept {
  max_order = std::clamp(max_order, 0, max_derivative_order);
  if (fast_eval<P>(*this, t, max_order, out)) return;
  DirBasis b[3];
  setup_basis<P>(*this, t, max_order, b);
  const bool rat = rational();
  const int H = dim_ + (rat ? 1 : 0);
  const int n1 = max_order + 1;
  double Abuf[27 * 64];
  std::vector<double> Aheap;
  double* A = Abuf;
  if (static_cast<std::size_t>(n1 * n1 * n1 * H) > std::size(Abuf)) {
    Aheap.resize(static_cast<std::size_t>(n1 * n1 * n1 * H));
    A = Aheap.data();
  }
  contract(points_.data(), rat ? weights_.data() : nullptr, dim_, b, max_order, A);

  const auto alphas = derivative_multi_indices<P>(max_order);
  auto Aat = [&](const std::array<int, P>& al) {
    int e[3] = {0, 0, 0};
    for (int d = 0; d < P; ++d) e[d] = al[static_cast<std::size_t>(d)];
    return A + ((e[2] * n1 + e[1]) * n1 + e[0]) * H;
  };
  for (std::size_t s = 0; s < alphas.size(); ++s) {
    const double* a = Aat(alphas[s]);
    double* o = out + s * static_cast<std::size_t>(dim_);
    for (int h = 0; h < dim_; ++h) o[h] = a[h];
  }
  if (!rat) return;
  // Quotient rule (NURBS Book eq. 4.8, extended to mixed partials):
  // C_alpha = (A_alpha - sum_{0 < beta <= alpha} binom(alpha, beta) w_beta C_{alpha-beta}) / w.
  const double w0 = Aat(alphas[0])[dim_];
  for (std::size_t s = 0; s < alphas.size(); ++s) {
    const auto& al = alphas[s];
    double* o = out + s * static_cast<std::size_t>(dim_);
    for (std::size_t r = 1; r <= s; ++r) {
      const auto& be = alphas[r];
      bool le = true;
      int coef = 1;
      std::array<int, P> diff{};
      for (int d = 0; d < P; ++d) {
        const auto dd = static_cast<std::size_t>(d);
        if (be[dd] > al[dd]) le = false;
        diff[dd] = al[dd] - be[dd];
        coef *= binom(al[dd], be[dd]);
      }
      if (!le) continue;
      const double wb = Aat(be)[dim_];
      const double* c = out + static_cast<std::size_t>(derivative_slot<P>(diff)) * static_cast<std::size_t>(dim_);
      for (int h = 0; h < dim_; ++h) o[h] -= coef * wb * c[h];
    }
    for (int h = 0; h < dim_; ++h) o[h] /= w0;
  }
}

template <int P>
std::vector<double> TensorSpline<P>::eval_derivatives(const Params& t, int max_order) const {
  max_order = std::clamp(max_order, 0, max_derivative_order);
  std::vector<double> out(static_cast<std::size_t>(derivative_count(P, max_order) * dim_));
  eval_derivatives(t, max_order, out.data());
  return out;
}

template <int P>
void TensorSpline<P>::eval_many(std::span<const double> params, std::span<double> out) const {
  const std::size_t n = params.size() / P;
  if (params.size() != n * P || out.size() != n * static_cast<std::size_t>(dim_))
    throw Error("eval_many: " + std::to_string(params.size()) + " parameter values and " +
                std::to_string(out.size()) + " outputs; expected n x " + std::to_string(P) + " and n x " +
                std::to_string(dim_));
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      Params t{};
      for (int d = 0; d < P; ++d) t[static_cast<std::size_t>(d)] = params[i * P + static_cast<std::size_t>(d)];
      eval(t, out.data() + i * static_cast<std::size_t>(dim_));
    }
  });
}

template <int P>
std::array<std::vector<double>, 2> TensorSpline<P>::control_box() const {
  std::array<std::vector<double>, 2> box{
      std::vector<double>(static_cast<std::size_t>(dim_), std::numeric_limits<double>::infinity()),
      std::vector<double>(static_cast<std::size_t>(dim_), -std::numeric_limits<double>::infinity())};
  for (int r = 0; r < size(); ++r) {
    const auto p = point(r);
    for (int h = 0; h < dim_; ++h) {
      box[0][static_cast<std::size_t>(h)] = std::min(box[0][static_cast<std::size_t>(h)], p[static_cast<std::size_t>(h)]);
      box[1][static_cast<std::size_t>(h)] = std::max(box[1][static_cast<std::size_t>(h)], p[static_cast<std::size_t>(h)]);
    }
  }
  return box;
}

template class TensorSpline<1>;
template class TensorSpline<2>;
template class TensorSpline<3>;
template std::span<const std::array<int, 1>> derivative_multi_indices<1>(int);
template std::span<const std::array<int, 2>> derivative_multi_indices<2>(int);
template std::span<const std::array<int, 3>> derivative_multi_indices<3>(int);
template int derivative_slot<1>(const std::array<int, 1>&);
template int derivative_slot<2>(const std::array<int, 2>&);
template int derivative_slot<3>(const std::array<int, 3>&);

}  // namespace trivox::spline
