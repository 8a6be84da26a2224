#include "trivox/spline/refine.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "tensor_ops.hpp"
#include "trivox/error.hpp"

namespace trivox::spline {

namespace {

using detail::Net;

/// A one-dimensional change of representation: the new knot vector and the (banded) matrix
/// taking old control points to new ones.
struct Map1D {
  KnotVector to;
  detail::Banded T;
};

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

Map1D identity_map(const KnotVector& kv) { return {kv, detail::Banded::identity(kv.size())}; }

/// Inserts `add` (sorted or not) into the map's target, composing the matrix, which stays banded
/// (a row of a refinement map has at most `order` non-zeros per original row's band): each new
/// row is Boehm's convex combination (NURBS Book A5.1). The knots go in in increasing order, so
/// the rows and knots are held as gap buffers split where the next knot goes (the rows before
/// it never change again, those after it only shift): O(n + k order) for k knots into n rows,
/// where inserting into flat vectors moved every later row and knot at each insertion.
/// A sequence held as a gap buffer split at a position that moves mostly forward: the part
/// before it in order, the part after it reversed (its next element at the back), so that
/// replacing elements at the split costs nothing for the rest.
template <class T>
struct GapBuffer {
  std::vector<T> left, right;

  std::size_t size() const noexcept { return left.size() + right.size(); }
  const T& at(std::size_t i) const { return i < left.size() ? left[i] : right[right.size() - 1 - (i - left.size())]; }
  /// Moves the split to `at` (0 <= at <= size()).
  void split(std::size_t at) {
    for (; left.size() < at; right.pop_back()) left.push_back(std::move(right.back()));
    for (; left.size() > at; left.pop_back()) right.push_back(std::move(left.back()));
  }
  /// The whole sequence, in order.
  std::vector<T> take() {
    split(size());
    return std::move(left);
  }
};

Map1D insert_into(Map1D m, std::vector<double> add) {
  std::sort(add.begin(), add.end());
  const int order = m.to.order();
  const int p = order - 1;
  struct Row {
    int first = 0;
    std::vector<double> c;  // T(i, first + k) = c[k]
  };
  const detail::Banded& B = m.T;
  GapBuffer<Row> rows;
  rows.left.reserve(static_cast<std::size_t>(B.rows()) + add.size());
  for (int j = B.rows() - 1; j >= 0; --j) {
    const auto uj = static_cast<std::size_t>(j);
    rows.right.push_back({B.first[uj], std::vector<double>(B.vals.begin() + static_cast<std::ptrdiff_t>(B.start[uj]),
                                                           B.vals.begin() + static_cast<std::ptrdiff_t>(B.start[uj + 1]))});
  }
  GapBuffer<double> knots;
  knots.right.assign(m.to.knots().rbegin(), m.to.knots().rend());
  knots.left.reserve(knots.right.size() + add.size());
  const auto knot = [&](int i) { return knots.at(static_cast<std::size_t>(i)); };
  const auto combine = [](const Row& x, double ax, const Row& y, double ay) {
    Row out;
    if (x.c.empty() && y.c.empty()) return out;
    const int lo = x.c.empty() ? y.first : y.c.empty() ? x.first : std::min(x.first, y.first);
    const int hi = std::max(x.c.empty() ? lo : x.first + static_cast<int>(x.c.size()),
                            y.c.empty() ? lo : y.first + static_cast<int>(y.c.size()));
    out.first = lo;
    out.c.assign(static_cast<std::size_t>(hi - lo), 0.0);
    for (std::size_t k = 0; k < out.c.size(); ++k) {
      const int col = lo + static_cast<int>(k);
      const double xv = col >= x.first && col < x.first + static_cast<int>(x.c.size()) ? x.c[static_cast<std::size_t>(col - x.first)] : 0.0;
      const double yv = col >= y.first && col < y.first + static_cast<int>(y.c.size()) ? y.c[static_cast<std::size_t>(col - y.first)] : 0.0;
      out.c[k] = ax * xv + ay * yv;
    }
    return out;
  };
  std::vector<Row> fresh;
  for (double t : add) {
    if (!(t >= m.to.front() && t <= m.to.back()))
      throw Error("knot " + num(t) + " outside the domain [" + num(m.to.front()) + ", " + num(m.to.back()) +
                  "]; expected a value inside it");
    // The knots <= t before the split; t's multiplicity is the run of equal knots just before it.
    while (!knots.right.empty() && knots.right.back() <= t) knots.split(knots.left.size() + 1);
    const int u = static_cast<int>(knots.left.size());
    int mult = 0;
    while (mult < u && knots.left[static_cast<std::size_t>(u - 1 - mult)] == t) ++mult;
    if (mult >= order)
      throw Error("knot " + num(t) + " already has multiplicity " + std::to_string(mult) +
                  "; expected at most the order (" + std::to_string(order) + ")");
    // The span t_mu <= t < t_mu+1 (at the right end: the last non-empty span), as KnotVector::find_span.
    const int n = static_cast<int>(knots.size()) - order;
    int mu = std::clamp(u - 1, p, n - 1);
    while (mu > p && knot(mu) == knot(mu + 1)) --mu;
    rows.split(static_cast<std::size_t>(mu) + 1);  // rows 0..mu before the split
    if (p == 0) {  // order 1: the basis function of span mu splits in two with the same coefficient
      rows.right.push_back(rows.left.back());
    } else {
      // Rows mu-p+1..mu become convex combinations (Boehm); the old row mu moves to mu+1.
      fresh.clear();
      for (int i = mu - p + 1; i <= mu; ++i) {
        const double ti = knot(i);
        const double a = (t - ti) / (knot(i + p) - ti);
        fresh.push_back(combine(rows.at(static_cast<std::size_t>(i)), a, rows.at(static_cast<std::size_t>(i - 1)), 1.0 - a));
      }
      Row last = std::move(rows.left.back());
      rows.left.resize(static_cast<std::size_t>(mu - p + 1));
      for (Row& r : fresh) rows.left.push_back(std::move(r));
      rows.right.push_back(std::move(last));
    }
    knots.split(static_cast<std::size_t>(mu) + 1);
    knots.left.push_back(t);
  }
  detail::Banded T;
  T.cols = B.cols;
  for (const Row& r : rows.take()) T.push_row(r.first, r.c.data(), r.c.size());
  m.T = std::move(T);
  m.to = KnotVector(order, knots.take());
  return m;
}

/// Keeps the basis functions first..first+count-1 and knots first..first+count+order-1.
Map1D select(Map1D m, int first, int count) {
  const int order = m.to.order();
  std::vector<double> knots(m.to.knots().begin() + first, m.to.knots().begin() + first + count + order);
  m.T = m.T.middle_rows(first, count);
  m.to = KnotVector(order, std::move(knots));
  return m;
}

/// Restriction to [a, b]: both ends raised to full multiplicity, the functions outside dropped.
Map1D restrict_map(const KnotVector& kv, double a, double b) {
  if (!(a >= kv.front() && b <= kv.back() && a < b))
    throw Error("sub-domain [" + num(a) + ", " + num(b) + "]; expected front <= a < b <= back with domain [" +
                num(kv.front()) + ", " + num(kv.back()) + "]");
  const int o = kv.order();
  std::vector<double> add;
  for (int r = kv.multiplicity(a); r < o; ++r) add.push_back(a);
  for (int r = kv.multiplicity(b); r < o; ++r) add.push_back(b);
  Map1D m = insert_into(identity_map(kv), std::move(add));
  const auto& t = m.to.knots();
  const int first = static_cast<int>(std::lower_bound(t.begin(), t.end(), a) - t.begin());
  const int last = static_cast<int>(std::upper_bound(t.begin(), t.end(), b) - t.begin());  // one past the last b
  return select(std::move(m), first, last - first - o);
}

Map1D clamp_map(const KnotVector& kv) {
  if (kv.clamped()) return identity_map(kv);
  return restrict_map(kv, kv.front(), kv.back());
}

Map1D elevate_map(const KnotVector& kv, int by) {
  if (by < 0) throw Error("degree elevation by " + std::to_string(by) + "; expected a non-negative amount");
  const Map1D c = clamp_map(kv);
  if (by == 0) return c;
  auto br = c.to.breakpoints();
  for (auto& b : br) b.multiplicity += by;
  const KnotVector to = KnotVector::from_breakpoints(kv.order() + by, br);
  // A clamped vector's clamp map is the identity: skip the dense product (cubic in the size,
  // minutes for the thousand-span curves of fillets).
  if (kv.clamped()) return {to, detail::Banded::from_dense(detail::transfer_matrix(c.to, to))};
  return {to, detail::Banded::from_dense(detail::transfer_matrix(c.to, to) * c.T.dense())};
}

template <int P>
void check_dir(const TensorSpline<P>& s, int dir) {
  (void)s;
  if (dir < 0 || dir >= P)
    throw Error("direction " + std::to_string(dir) + "; expected 0.." + std::to_string(P - 1));
}

template <int P>
TensorSpline<P> apply_map(const TensorSpline<P>& s, int dir, const Map1D& m) {
  auto net = detail::apply_along(detail::to_net(s), dir, m.T);
  auto knots = s.knot_vectors();
  knots[static_cast<std::size_t>(dir)] = m.to;
  return detail::from_net<P>(std::move(knots), s.dim(), s.rational(), std::move(net));
}

}  // namespace

template <int P>
TensorSpline<P> insert_knot(const TensorSpline<P>& s, int dir, double t, int times) {
  check_dir(s, dir);
  if (times < 0) throw Error("insert a knot " + std::to_string(times) + " times; expected a non-negative count");
  return apply_map(s, dir, insert_into(identity_map(s.knots(dir)), std::vector<double>(static_cast<std::size_t>(times), t)));
}

template <int P>
TensorSpline<P> refine(const TensorSpline<P>& s, int dir, std::span<const double> knots) {
  check_dir(s, dir);
  return apply_map(s, dir, insert_into(identity_map(s.knots(dir)), std::vector<double>(knots.begin(), knots.end())));
}

template <int P>
TensorSpline<P> refine_uniform(const TensorSpline<P>& s, int dir, int per_span) {
  check_dir(s, dir);
  std::vector<double> add;
  const auto br = s.knots(dir).breakpoints();
  for (std::size_t i = 0; i + 1 < br.size(); ++i)
    for (int k = 1; k <= per_span; ++k)
      add.push_back(br[i].value + (br[i + 1].value - br[i].value) * k / (per_span + 1));
  return refine(s, dir, add);
}

template <int P>
TensorSpline<P> elevate(const TensorSpline<P>& s, int dir, int by) {
  check_dir(s, dir);
  return apply_map(s, dir, elevate_map(s.knots(dir), by));
}

template <int P>
TensorSpline<P> clamp(const TensorSpline<P>& s, int dir) {
  check_dir(s, dir);
  if (s.knots(dir).clamped()) return s;
  return apply_map(s, dir, clamp_map(s.knots(dir)));
}

template <int P>
TensorSpline<P> clamp(const TensorSpline<P>& s) {
  TensorSpline<P> out = s;
  for (int d = 0; d < P; ++d) out = clamp(out, d);
  return out;
}

namespace {
/// The map of to_bezier_form(s, dir) along a knot vector; nullopt where it is the identity
/// (a clamped vector with every knot at full multiplicity).
std::optional<Map1D> bezier_map(const KnotVector& kv) {
  const Map1D c = clamp_map(kv);
  std::vector<double> add;
  for (const auto& b : c.to.breakpoints())
    for (int r = b.multiplicity; r < kv.order(); ++r) add.push_back(b.value);
  if (add.empty() && kv.clamped()) return std::nullopt;
  return insert_into(c, std::move(add));
}
}  // namespace

template <int P>
TensorSpline<P> to_bezier_form(const TensorSpline<P>& s, int dir) {
  check_dir(s, dir);
  // Already in Bezier form along dir: applying the identity would only copy the net, twice.
  const auto m = bezier_map(s.knots(dir));
  return m ? apply_map(s, dir, *m) : s;
}

template <int P>
TensorSpline<P> to_bezier_form(const TensorSpline<P>& s) {
  if (s.rational()) {  // each direction's homogeneous round trip kept: the same floats as before
    TensorSpline<P> b = s;
    for (int d = 0; d < P; ++d) b = to_bezier_form(b, d);
    return b;
  }
  // One net through the P maps: the same sums as direction by direction (a polynomial net is
  // the points themselves), without a copy of the net and a spline per direction.
  std::optional<detail::Net<P>> net;
  auto knots = s.knot_vectors();
  for (int d = 0; d < P; ++d) {
    const auto m = bezier_map(s.knots(d));
    if (!m) continue;
    // (Not `net ? *net : to_net(s)`: that conditional is a prvalue, a copy of *net.)
    net = net ? detail::apply_along(*net, d, m->T) : detail::apply_along(detail::to_net(s), d, m->T);
    knots[static_cast<std::size_t>(d)] = m->to;
  }
  return net ? detail::from_net<P>(std::move(knots), s.dim(), false, std::move(*net)) : s;
}

template <int P>
std::vector<TensorSpline<P>> bezier_pieces(const TensorSpline<P>& s) {
  const TensorSpline<P> b = to_bezier_form(s);
  // In Bezier form the pieces are disjoint blocks of the control net.
  std::array<std::vector<double>, P> breaks;
  std::array<int, P> spans{};
  for (int d = 0; d < P; ++d) {
    for (const auto& br : b.knots(d).breakpoints()) breaks[static_cast<std::size_t>(d)].push_back(br.value);
    spans[static_cast<std::size_t>(d)] = static_cast<int>(breaks[static_cast<std::size_t>(d)].size()) - 1;
  }
  int total = 1;
  for (int d = 0; d < P; ++d) total *= spans[static_cast<std::size_t>(d)];
  std::vector<TensorSpline<P>> out;
  out.reserve(static_cast<std::size_t>(total));
  const auto orders = b.orders();
  for (int e = 0; e < total; ++e) {
    const auto el = detail::piece_element<P>(e, spans);
    std::array<KnotVector, P> knots;
    int n = 1;
    for (int d = 0; d < P; ++d) {
      const auto dd = static_cast<std::size_t>(d);
      knots[dd] = KnotVector::bezier(orders[dd], breaks[dd][static_cast<std::size_t>(el[dd])],
                                     breaks[dd][static_cast<std::size_t>(el[dd]) + 1]);
      n *= orders[dd];
    }
    std::vector<double> pts(static_cast<std::size_t>(n * s.dim()));
    std::vector<double> w(b.rational() ? static_cast<std::size_t>(n) : 0);
    for (int r = 0; r < n; ++r) {
      const auto src = detail::piece_point<P>(el, r, orders);
      const int sr = b.row(src);
      std::copy_n(b.point(sr).data(), s.dim(), pts.data() + static_cast<std::ptrdiff_t>(r) * s.dim());
      if (b.rational()) w[static_cast<std::size_t>(r)] = b.weights()[static_cast<std::size_t>(sr)];
    }
    out.emplace_back(std::move(knots), s.dim(), std::move(pts), std::move(w));
  }
  return out;
}

template <int P>
std::pair<TensorSpline<P>, TensorSpline<P>> split(const TensorSpline<P>& s, int dir, double t) {
  check_dir(s, dir);
  const KnotVector& kv = s.knots(dir);
  if (!(t > kv.front() && t < kv.back()))
    throw Error("split at " + num(t) + "; expected a parameter strictly inside (" + num(kv.front()) + ", " +
                num(kv.back()) + ")");
  return {restrict_to(s, dir, kv.front(), t), restrict_to(s, dir, t, kv.back())};
}

template <int P>
TensorSpline<P> restrict_to(const TensorSpline<P>& s, int dir, double a, double b) {
  check_dir(s, dir);
  return apply_map(s, dir, restrict_map(s.knots(dir), a, b));
}

template <int P>
TensorSpline<P> reparametrize(const TensorSpline<P>& s, int dir, double a, double b) {
  check_dir(s, dir);
  if (!(a < b) || !std::isfinite(a) || !std::isfinite(b))
    throw Error("reparametrisation to [" + num(a) + ", " + num(b) + "]; expected finite a < b");
  const KnotVector& kv = s.knots(dir);
  const double f = kv.front(), g = kv.back();
  std::vector<double> k = kv.knots();
  for (double& t : k) t = (t == f) ? a : (t == g) ? b : a + (t - f) * (b - a) / (g - f);
  auto knots = s.knot_vectors();
  knots[static_cast<std::size_t>(dir)] = KnotVector(kv.order(), std::move(k));
  return TensorSpline<P>(std::move(knots), s.dim(), std::vector<double>(s.points().begin(), s.points().end()), s.weights());
}

template <int P>
TensorSpline<P> reverse(const TensorSpline<P>& s, int dir) {
  check_dir(s, dir);
  const KnotVector& kv = s.knots(dir);
  const double f = kv.front(), g = kv.back();
  std::vector<double> k(kv.knots().rbegin(), kv.knots().rend());
  for (double& t : k) t = f + g - t;
  auto knots = s.knot_vectors();
  knots[static_cast<std::size_t>(dir)] = KnotVector(kv.order(), std::move(k));
  // A permutation of the control points: exact, also for rational splines.
  TensorSpline<P> out(std::move(knots), s.dim(), std::vector<double>(s.points().begin(), s.points().end()), s.weights());
  const int n = kv.size();
  for (int r = 0; r < s.size(); ++r) {
    auto i = s.multi_index(r);
    i[static_cast<std::size_t>(dir)] = n - 1 - i[static_cast<std::size_t>(dir)];
    const int q = out.row(i);
    std::copy_n(s.point(r).data(), s.dim(), out.point(q).data());
    if (s.rational()) out.weights()[static_cast<std::size_t>(q)] = s.weights()[static_cast<std::size_t>(r)];
  }
  return out;
}

template <int P>
TensorSpline<P> swap_directions(const TensorSpline<P>& s, int d1, int d2) {
  check_dir(s, d1);
  check_dir(s, d2);
  if (d1 == d2) return s;
  auto knots = s.knot_vectors();
  std::swap(knots[static_cast<std::size_t>(d1)], knots[static_cast<std::size_t>(d2)]);
  TensorSpline<P> out(knots, s.dim(), std::vector<double>(s.points().begin(), s.points().end()), s.weights());
  for (int r = 0; r < s.size(); ++r) {
    auto i = s.multi_index(r);
    std::swap(i[static_cast<std::size_t>(d1)], i[static_cast<std::size_t>(d2)]);
    const int q = out.row(i);
    std::copy_n(s.point(r).data(), s.dim(), out.point(q).data());
    if (s.rational()) out.weights()[static_cast<std::size_t>(q)] = s.weights()[static_cast<std::size_t>(r)];
  }
  return out;
}

template <int P>
TensorSpline<P> to_space(const TensorSpline<P>& s, int dir, const KnotVector& target) {
  check_dir(s, dir);
  if (s.knots(dir) == target) return s;
  if (s.knots(dir).clamped())
    return apply_map(s, dir, Map1D{target, detail::Banded::from_dense(detail::transfer_matrix(s.knots(dir), target))});
  const Map1D c = clamp_map(s.knots(dir));
  return apply_map(s, dir, Map1D{target, detail::Banded::from_dense(detail::transfer_matrix(c.to, target) * c.T.dense())});
}

template <int P>
std::pair<TensorSpline<P>, TensorSpline<P>> make_compatible(const TensorSpline<P>& a, const TensorSpline<P>& b) {
  TensorSpline<P> x = a, y = b;
  for (int d = 0; d < P; ++d) {
    const KnotVector& ka = a.knots(d);
    const KnotVector& kb = b.knots(d);
    if (ka == kb) continue;
    if (ka.front() != kb.front() || ka.back() != kb.back())
      throw Error("direction " + std::to_string(d) + " has domains [" + num(ka.front()) + ", " + num(ka.back()) +
                  "] and [" + num(kb.front()) + ", " + num(kb.back()) + "]; expected equal domains (reparametrise first)");
    const KnotVector common = detail::merged_space(clamp_map(ka).to, clamp_map(kb).to, std::max(ka.order(), kb.order()));
    x = to_space(x, d, common);
    y = to_space(y, d, common);
  }
  return {std::move(x), std::move(y)};
}

#define TRIVOX_INSTANTIATE(P)                                                                             \
  template TensorSpline<P> insert_knot(const TensorSpline<P>&, int, double, int);                         \
  template TensorSpline<P> refine(const TensorSpline<P>&, int, std::span<const double>);                  \
  template TensorSpline<P> refine_uniform(const TensorSpline<P>&, int, int);                              \
  template TensorSpline<P> elevate(const TensorSpline<P>&, int, int);                                     \
  template TensorSpline<P> clamp(const TensorSpline<P>&, int);                                            \
  template TensorSpline<P> clamp(const TensorSpline<P>&);                                                 \
  template TensorSpline<P> to_bezier_form(const TensorSpline<P>&, int);                                   \
  template TensorSpline<P> to_bezier_form(const TensorSpline<P>&);                                        \
  template std::vector<TensorSpline<P>> bezier_pieces(const TensorSpline<P>&);                            \
  template std::pair<TensorSpline<P>, TensorSpline<P>> split(const TensorSpline<P>&, int, double);        \
  template TensorSpline<P> restrict_to(const TensorSpline<P>&, int, double, double);                      \
  template TensorSpline<P> reparametrize(const TensorSpline<P>&, int, double, double);                    \
  template TensorSpline<P> reverse(const TensorSpline<P>&, int);                                          \
  template TensorSpline<P> swap_directions(const TensorSpline<P>&, int, int);                             \
  template TensorSpline<P> to_space(const TensorSpline<P>&, int, const KnotVector&);                      \
  template std::pair<TensorSpline<P>, TensorSpline<P>> make_compatible(const TensorSpline<P>&, const TensorSpline<P>&);
TRIVOX_INSTANTIATE(1)
TRIVOX_INSTANTIATE(2)
TRIVOX_INSTANTIATE(3)
#undef TRIVOX_INSTANTIATE

}  // namespace trivox::spline
