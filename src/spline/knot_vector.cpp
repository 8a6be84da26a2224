#include "trivox/spline/knot_vector.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "trivox/error.hpp"
#include "trivox/limits.hpp"

namespace trivox::spline {

namespace {
std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}
}  // namespace

KnotVector::KnotVector(int order, std::vector<double> knots) : order_(order), knots_(std::move(knots)) {
  if (order_ < 1)
    throw Error("order " + std::to_string(order_) + "; expected an order (degree + 1) of at least 1");
  const auto m = static_cast<int>(knots_.size());
  if (m < 2 * order_)
    throw Error(std::to_string(m) + " knots for order " + std::to_string(order_) +
                "; expected at least " + std::to_string(2 * order_) +
                " (control points + order, with at least order control points)");
  for (int i = 0; i < m; ++i) {
    if (!std::isfinite(knots_[i]))
      throw Error("knot " + std::to_string(i) + " is " + num(knots_[i]) + "; expected a finite number");
    if (i > 0 && knots_[i] < knots_[i - 1])
      throw Error("knot " + std::to_string(i) + " is " + num(knots_[i]) + ", less than knot " +
                  std::to_string(i - 1) + " (" + num(knots_[i - 1]) + "); expected non-decreasing knots");
  }
  if (!(front() < back()))
    throw Error("empty domain [" + num(front()) + ", " + num(back()) + "]; expected knot " +
                std::to_string(order_ - 1) + " < knot " + std::to_string(size()));
  // Interior multiplicity above `order` would make a basis function identically zero.
  for (int i = 0; i + order_ < m; ++i)
    if (knots_[i] == knots_[i + order_])
      throw Error("knot value " + num(knots_[i]) + " repeated more than " + std::to_string(order_) +
                  " times from knot " + std::to_string(i) + "; expected multiplicity <= order");
  // Reciprocal knot differences per span for the divisions of Cox-de Boor (zero for empty spans,
  // which find_span never returns).
  const int p = order_ - 1;
  const std::int64_t tri = std::int64_t{p} * (p + 1) / 2, entries = (size() - p) * tri;
  // spans x order^2 / 2 doubles: bounded by the input limits before a byte is allocated. The
  // lock of default_limits is taken only for tables beyond a million entries (8 MB), which no
  // model of the repository comes near.
  if (entries > (std::int64_t{1} << 20)) {
    const std::int64_t most = default_limits().max_points;
    if (entries > most)
      throw Error("order " + std::to_string(order_) + " over " + std::to_string(size() - p) + " spans: " +
                  std::to_string(entries) + " knot differences for Cox-de Boor (spans x order x (order - 1) / 2); expected at most " +
                  std::to_string(most) + limit_hint("max_points"));
  }
  inv_.assign(static_cast<std::size_t>(entries), 0.0);
  for (int mu = p; mu < size(); ++mu) {
    if (!(knots_[static_cast<std::size_t>(mu)] < knots_[static_cast<std::size_t>(mu) + 1])) continue;
    double* iv = inv_.data() + (mu - p) * tri;
    for (int j = 1; j <= p; ++j)
      for (int r = 0; r < j; ++r)
        iv[j * (j - 1) / 2 + r] = 1.0 / (knots_[static_cast<std::size_t>(mu + r + 1)] - knots_[static_cast<std::size_t>(mu + 1 - j + r)]);
  }
}

KnotVector KnotVector::uniform(int order, int segments, double a, double b) {
  if (segments < 1) throw Error("uniform knot vector with " + std::to_string(segments) + " segments; expected >= 1");
  std::vector<double> k;
  k.reserve(static_cast<std::size_t>(2 * order + segments - 1));
  for (int i = 0; i < order; ++i) k.push_back(a);
  for (int i = 1; i < segments; ++i) k.push_back(a + (b - a) * i / segments);
  for (int i = 0; i < order; ++i) k.push_back(b);
  return KnotVector(order, std::move(k));
}

KnotVector KnotVector::bezier(int order, double a, double b) { return uniform(order, 1, a, b); }

KnotVector KnotVector::from_breakpoints(int order, std::span<const Breakpoint> breaks) {
  std::vector<double> k;
  for (std::size_t i = 0; i < breaks.size(); ++i) {
    const int m = (i == 0 || i + 1 == breaks.size()) ? order : breaks[i].multiplicity;
    for (int r = 0; r < m; ++r) k.push_back(breaks[i].value);
  }
  return KnotVector(order, std::move(k));
}

bool KnotVector::clamped() const noexcept {
  const auto m = knots_.size();
  const auto o = static_cast<std::size_t>(order_);
  return knots_[0] == knots_[o - 1] && knots_[m - 1] == knots_[m - o];
}

std::vector<Breakpoint> KnotVector::breakpoints() const {
  std::vector<Breakpoint> out;
  const double a = front(), b = back();
  for (std::size_t i = 0; i < knots_.size();) {
    std::size_t j = i;
    while (j < knots_.size() && knots_[j] == knots_[i]) ++j;
    if (knots_[i] >= a && knots_[i] <= b) out.push_back({knots_[i], static_cast<int>(j - i)});
    i = j;
  }
  return out;
}

int KnotVector::multiplicity(double t) const noexcept {
  const auto r = std::equal_range(knots_.begin(), knots_.end(), t);
  return static_cast<int>(r.second - r.first);
}

int KnotVector::find_span(double t) const noexcept {
  const int n = size();
  if (!(t > front())) t = front();  // also maps NaN to the front
  if (t >= back()) {
    // The last non-empty span ending at back().
    int mu = n - 1;
    while (mu > order_ - 1 && knots_[static_cast<std::size_t>(mu)] == back()) --mu;
    return mu;
  }
  // upper_bound gives the first knot > t; the span starts one before it.
  const auto it = std::upper_bound(knots_.begin() + order_ - 1, knots_.begin() + n + 1, t);
  return static_cast<int>(it - knots_.begin()) - 1;
}

int KnotVector::find_span(double t, int hint) const noexcept {
  if (hint >= order_ - 1 && hint < size()) {
    const double lo = knots_[static_cast<std::size_t>(hint)];
    const double hi = knots_[static_cast<std::size_t>(hint) + 1];
    if (t >= lo && t < hi) return hint;
    if (t == hi && hint == size() - 1) return hint;  // right end of the domain
  }
  return find_span(t);
}

namespace {

/// Cox-de Boor up to degree p (NURBS Book A2.2, with the left/right differences) on knots `k`
/// around span mu; `P` = p when known at compile time (the loops unroll), else -1.
/// `iv`: the span's reciprocal knot differences 1 / (t_{mu+r+1} - t_{mu+1-j+r}) at
/// [j(j-1)/2 + r], which equal 1 / (R[r+1] + L[j-r]) for every t: no division per evaluation.
template <int Pc>
inline void cox_de_boor(const double* k, const double* iv, int mu, double t, int p, double* out, double* L, double* R) {
  if constexpr (Pc >= 0) p = Pc;
  out[0] = 1.0;
  for (int j = 1; j <= p; ++j) {
    L[j] = t - k[mu + 1 - j];
    R[j] = k[mu + j] - t;
    double saved = 0.0;
    const double* ivj = iv + j * (j - 1) / 2;
    for (int r = 0; r < j; ++r) {
      const double tmp = out[r] * ivj[r];
      out[r] = saved + R[r + 1] * tmp;
      saved = L[j - r] * tmp;
    }
    out[j] = saved;
  }
}

/// Values and first derivatives of the degree-p functions: the degree p-1 values M, then
/// N'_{i,p} = p (M_{i-1} / (t_{i+p} - t_i) - M_i / (t_{i+p+1} - t_{i+1})) (NURBS Book eq. 2.9)
/// and the last Cox-de Boor step for the values.
template <int Pc>
inline void values_and_slopes(const double* k, const double* iv, int mu, double t, int p, double* out, double* L, double* R) {
  if constexpr (Pc >= 0) p = Pc;
  double* val = out;
  double* der = out + p + 1;
  cox_de_boor<(Pc > 0 ? Pc - 1 : -1)>(k, iv, mu, t, p - 1, val, L, R);
  // der_j from M_{j-1}, M_j (val holds M_0..M_{p-1}); 1 / (t_{mu+j+1} - t_{mu-p+j+1}) is row p
  // of the reciprocal table.
  const double* ivp = iv + p * (p - 1) / 2;
  double prev = 0.0;  // M_{j-1} / (t_{mu+j} - t_{mu-p+j})
  for (int j = 0; j < p; ++j) {
    const double q = val[j] * ivp[j];
    der[j] = p * (prev - q);
    prev = q;
  }
  der[p] = p * prev;
  // Raise the values to degree p.
  L[p] = t - k[mu + 1 - p];
  R[p] = k[mu + p] - t;
  double saved = 0.0;
  for (int r = 0; r < p; ++r) {
    const double tmp = val[r] * ivp[r];
    val[r] = saved + R[r + 1] * tmp;
    saved = L[p - r] * tmp;
  }
  val[p] = saved;
}

}  // namespace

void KnotVector::basis(int span, double t, double* out) const noexcept {
  const int p = order_ - 1;
  double L[16], R[16];
  const double* k = knots_.data();
  const double* iv = span_reciprocals(span);
  switch (p) {
    case 0: out[0] = 1.0; return;
    case 1: return cox_de_boor<1>(k, iv, span, t, p, out, L, R);
    case 2: return cox_de_boor<2>(k, iv, span, t, p, out, L, R);
    case 3: return cox_de_boor<3>(k, iv, span, t, p, out, L, R);
    case 4: return cox_de_boor<4>(k, iv, span, t, p, out, L, R);
    case 5: return cox_de_boor<5>(k, iv, span, t, p, out, L, R);
    default: break;
  }
  if (p < 16) return cox_de_boor<-1>(k, iv, span, t, p, out, L, R);
  std::vector<double> heap(2 * static_cast<std::size_t>(p + 1));
  cox_de_boor<-1>(k, iv, span, t, p, out, heap.data(), heap.data() + p + 1);
}

void KnotVector::basis_derivatives(int span, double t, int nder, double* out) const noexcept {
  // NURBS Book A2.3: the triangle of basis values of all degrees, then derivatives from the
  // differences of the lower-degree functions.
  const int p = order_ - 1;
  const int o = order_;
  if (nder == 1 && p >= 1 && p < 16) {
    // The common case (first partials) without the full derivative triangle.
    double L[16], R[16];
    const double* k = knots_.data();
    const double* iv = span_reciprocals(span);
    switch (p) {
      case 1: return values_and_slopes<1>(k, iv, span, t, p, out, L, R);
      case 2: return values_and_slopes<2>(k, iv, span, t, p, out, L, R);
      case 3: return values_and_slopes<3>(k, iv, span, t, p, out, L, R);
      case 4: return values_and_slopes<4>(k, iv, span, t, p, out, L, R);
      default: return values_and_slopes<-1>(k, iv, span, t, p, out, L, R);
    }
  }
  const int requested = nder;
  nder = std::min(nder, p);
  // Only the values of degrees p - nder .. p are needed (columns of A2.3's triangle), and its
  // lower half, the knot differences, is recomputed from left and right: O(order) memory where
  // A2.3 takes O(order^2) (an order of 20000 took 1.6 GB per evaluation). Same operations in
  // the same order, so the same bits. Stack storage for the usual orders.
  constexpr int stack_order = 16;
  double stack[(max_derivative_order + 4) * stack_order];
  std::vector<double> heap;
  double* buffer = stack;
  if (o > stack_order) {
    heap.resize(static_cast<std::size_t>((nder + 4) * o));
    buffer = heap.data();
  }
  double* left = buffer;
  double* right = left + o;
  double* N = right + o;       // the values of degree j, updated in place
  double* cols = N + o;        // cols[(j - (p - nder)) * o + r]: N_r of degree j >= p - nder
  auto value = [&](int r, int j) { return cols[(j - (p - nder)) * o + r]; };
  auto difference = [&](int j, int r) { return right[r + 1] + left[j - r]; };  // A2.3's ndu[j][r], r < j
  N[0] = 1.0;
  if (p - nder == 0) cols[0] = 1.0;
  for (int j = 1; j <= p; ++j) {
    left[j] = t - knots_[static_cast<std::size_t>(span + 1 - j)];
    right[j] = knots_[static_cast<std::size_t>(span + j)] - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      const double tmp = N[r] / difference(j, r);
      N[r] = saved + right[r + 1] * tmp;
      saved = left[j - r] * tmp;
    }
    N[j] = saved;
    if (j >= p - nder) std::copy(N, N + j + 1, cols + (j - (p - nder)) * o);
  }
  for (int j = 0; j <= p; ++j) out[j] = value(j, p);
  double a[2][max_derivative_order + 1];
  for (int r = 0; r <= p; ++r) {
    int s1 = 0, s2 = 1;
    for (auto& row : a) std::fill(std::begin(row), std::end(row), 0.0);
    a[0][0] = 1.0;
    for (int k = 1; k <= nder; ++k) {
      double d = 0.0;
      const int rk = r - k, pk = p - k;
      if (r >= k) {
        a[s2][0] = a[s1][0] / difference(pk + 1, rk);
        d = a[s2][0] * value(rk, pk);
      }
      const int j1 = (rk >= -1) ? 1 : -rk;
      const int j2 = (r - 1 <= pk) ? k - 1 : p - r;
      for (int j = j1; j <= j2; ++j) {
        a[s2][j] = (a[s1][j] - a[s1][j - 1]) / difference(pk + 1, rk + j);
        d += a[s2][j] * value(rk + j, pk);
      }
      if (r <= pk) {
        a[s2][k] = -a[s1][k - 1] / difference(pk + 1, r);
        d += a[s2][k] * value(r, pk);
      }
      out[k * o + r] = d;
      std::swap(s1, s2);
    }
  }
  int factor = p;
  for (int k = 1; k <= nder; ++k) {
    for (int j = 0; j <= p; ++j) out[k * o + j] *= factor;
    factor *= (p - k);
  }
  // Derivatives above the degree vanish.
  for (int k = nder + 1; k <= requested; ++k)
    for (int j = 0; j <= p; ++j) out[k * o + j] = 0.0;
}

std::vector<double> KnotVector::greville() const {
  std::vector<double> g(static_cast<std::size_t>(size()));
  const int p = degree();
  for (int i = 0; i < size(); ++i) {
    if (p == 0) {
      g[static_cast<std::size_t>(i)] = 0.5 * (knots_[static_cast<std::size_t>(i)] + knots_[static_cast<std::size_t>(i) + 1]);
      continue;
    }
    double s = 0.0;
    for (int j = 1; j <= p; ++j) s += knots_[static_cast<std::size_t>(i + j)];
    g[static_cast<std::size_t>(i)] = s / p;
  }
  return g;
}

}  // namespace trivox::spline
