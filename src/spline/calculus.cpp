#include "trivox/spline/calculus.hpp"

#include <string>

#include "banded_qr.hpp"

#include "tensor_ops.hpp"
#include "trivox/error.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::spline {

namespace {

template <int P>
void require_polynomial(const TensorSpline<P>& s, const char* what) {
  if (s.rational())
    throw Error(std::string(what) + " of a rational spline; expected a polynomial (non-rational) spline");
}

/// The net of coefficients in `kv` whose values at `samples` along direction d are `net`'s: the
/// least-squares solution of the collocation system, one right-hand side per line of the net.
/// The collocation matrix is banded (`order` non-zeros per sample, samples sorted), so it is
/// solved by sequential Givens rotations (detail::BandedQR): linear in the number of spans, where
/// the dense pseudo-inverse was cubic (minutes, and gigabytes, for the thousand-span fillet
/// cells' Jacobian products), and orthogonal like it (no squared condition number).
template <int P>
detail::Net<P> solve_along(const detail::Net<P>& net, int d, const KnotVector& kv, const std::vector<double>& samples) {
  const auto dd = static_cast<std::size_t>(d);
  const int m = net.extents[dd], n = kv.size(), order = kv.order();
  // Lines of the net: entries between neighbours along d (inner, times the H coordinates) and
  // blocks of lines (outer), as in detail::apply_along.
  std::ptrdiff_t inner = 1, outer = 1;
  for (int e = 0; e < d; ++e) inner *= net.extents[static_cast<std::size_t>(e)];
  for (int e = d + 1; e < P; ++e) outer *= net.extents[static_cast<std::size_t>(e)];
  const std::ptrdiff_t line = inner * net.H, r = outer * line;
  detail::BandedQR qr(n, order, r);
  std::vector<double> N(static_cast<std::size_t>(order));
  Eigen::RowVectorXd rhs(r);
  for (int i = 0; i < m; ++i) {
    const double t = samples[static_cast<std::size_t>(i)];
    const int mu = kv.find_span(t);
    kv.basis(mu, t, N.data());
    for (std::ptrdiff_t o = 0; o < outer; ++o)
      for (std::ptrdiff_t k = 0; k < line; ++k) rhs(o * line + k) = net.values[static_cast<std::size_t>((o * m + i) * line + k)];
    qr.add_row(mu - order + 1, N, rhs);
  }
  const Eigen::MatrixXd X =
      qr.solve({"product", ErrorKind::failed, "a product space that the samples determine",
                [](int c) { return "coefficient " + std::to_string(c); }});
  detail::Net<P> out;
  out.extents = net.extents;
  out.extents[dd] = n;
  out.H = net.H;
  out.values.resize(static_cast<std::size_t>(outer * n * line));
  for (std::ptrdiff_t o = 0; o < outer; ++o)
    for (int i = 0; i < n; ++i)
      for (std::ptrdiff_t k = 0; k < line; ++k) out.values[static_cast<std::size_t>((o * n + i) * line + k)] = X(i, o * line + k);
  return out;
}

}  // namespace

template <int P>
TensorSpline<P> derivative(const TensorSpline<P>& s, int dir) {
  require_polynomial(s, "derivative");
  if (dir < 0 || dir >= P) throw Error("direction " + std::to_string(dir) + "; expected 0.." + std::to_string(P - 1));
  const KnotVector& kv = s.knots(dir);
  const int p = kv.degree();
  if (p < 1) throw Error("derivative of a piecewise constant (order 1) direction; expected order >= 2");
  const auto& t = kv.knots();
  const int n = kv.size();
  // Divided differences p (P_{i+1} - P_i) / (t_{i+p+1} - t_{i+1}), NURBS Book eq. 3.8. Where the
  // denominator vanishes (a knot of multiplicity `order`) the basis function of that
  // coefficient is identically zero: drop it with one copy of the knot.
  std::vector<double> knots;
  std::vector<int> keep;
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(n - 1, n);
  for (int i = 0; i + 1 < n; ++i) {
    const double h = t[static_cast<std::size_t>(i + p + 1)] - t[static_cast<std::size_t>(i + 1)];
    if (h > 0.0) {
      D(i, i + 1) = p / h;
      D(i, i) = -p / h;
      keep.push_back(i);
    }
  }
  // Knots of the derivative: t_1 .. t_{n+p-1}, minus one copy per dropped coefficient.
  std::vector<double> all(t.begin() + 1, t.end() - 1);
  for (int i = n - 2; i >= 0; --i)
    if (std::find(keep.begin(), keep.end(), i) == keep.end()) all.erase(all.begin() + i + 1);
  Eigen::MatrixXd Dk(static_cast<Eigen::Index>(keep.size()), n);
  for (std::size_t r = 0; r < keep.size(); ++r) Dk.row(static_cast<Eigen::Index>(r)) = D.row(keep[r]);
  auto net = detail::apply_along(detail::to_net(s), dir, Dk);
  auto kvs = s.knot_vectors();
  kvs[static_cast<std::size_t>(dir)] = KnotVector(p, std::move(all));
  return detail::from_net<P>(std::move(kvs), s.dim(), false, std::move(net));
}

template <int P>
TensorSpline<P> product(const TensorSpline<P>& a, const TensorSpline<P>& b, ProductKind kind) {
  require_polynomial(a, "product");
  require_polynomial(b, "product");
  const int ka = a.dim(), kb = b.dim();
  int dim = 0;
  switch (kind) {
    case ProductKind::scalar: dim = (ka == 1 && kb == 1) ? 1 : 0; break;
    case ProductKind::scalar_vector: dim = (ka == 1) ? kb : 0; break;
    case ProductKind::dot: dim = (ka == kb) ? 1 : 0; break;
    case ProductKind::cross: dim = (ka == 3 && kb == 3) ? 3 : 0; break;
    case ProductKind::componentwise: dim = (ka == kb) ? ka : 0; break;
  }
  if (dim == 0)
    throw Error("product of splines with " + std::to_string(ka) + " and " + std::to_string(kb) +
                " coordinates; expected scalar*scalar (1,1), scalar*vector (1,k), dot or componentwise (k,k), "
                "cross (3,3)");
  std::array<KnotVector, P> knots;
  std::array<std::vector<double>, P> samples;
  std::array<int, P> ns{};
  for (int d = 0; d < P; ++d) {
    const auto dd = static_cast<std::size_t>(d);
    const KnotVector& x = a.knots(d);
    const KnotVector& y = b.knots(d);
    if (x.front() != y.front() || x.back() != y.back())
      throw Error("product of splines on different domains in direction " + std::to_string(d) +
                  "; expected equal domains");
    knots[dd] = detail::merged_space(clamp(a, d).knots(d), clamp(b, d).knots(d), x.order() + y.order() - 1);
    samples[dd] = detail::span_samples(knots[dd], knots[dd].order());
    ns[dd] = static_cast<int>(samples[dd].size());
  }
  // Values of the product on the sample grid (first direction fastest).
  detail::Net<P> net;
  net.extents = ns;
  net.H = dim;
  std::size_t total = 1;
  for (int d = 0; d < P; ++d) total *= static_cast<std::size_t>(ns[static_cast<std::size_t>(d)]);
  net.values.resize(total * static_cast<std::size_t>(dim));
  std::vector<double> va(static_cast<std::size_t>(ka)), vb(static_cast<std::size_t>(kb));
  for (std::size_t g = 0; g < total; ++g) {
    std::array<double, P> t{};
    std::size_t rest = g;
    for (int d = 0; d < P; ++d) {
      const auto dd = static_cast<std::size_t>(d);
      t[dd] = samples[dd][rest % static_cast<std::size_t>(ns[dd])];
      rest /= static_cast<std::size_t>(ns[dd]);
    }
    a.eval(t, va.data());
    b.eval(t, vb.data());
    double* o = net.values.data() + g * static_cast<std::size_t>(dim);
    switch (kind) {
      case ProductKind::scalar: o[0] = va[0] * vb[0]; break;
      case ProductKind::scalar_vector:
        for (int h = 0; h < kb; ++h) o[h] = va[0] * vb[static_cast<std::size_t>(h)];
        break;
      case ProductKind::dot:
        o[0] = 0.0;
        for (int h = 0; h < ka; ++h) o[0] += va[static_cast<std::size_t>(h)] * vb[static_cast<std::size_t>(h)];
        break;
      case ProductKind::cross:
        o[0] = va[1] * vb[2] - va[2] * vb[1];
        o[1] = va[2] * vb[0] - va[0] * vb[2];
        o[2] = va[0] * vb[1] - va[1] * vb[0];
        break;
      case ProductKind::componentwise:
        for (int h = 0; h < ka; ++h) o[h] = va[static_cast<std::size_t>(h)] * vb[static_cast<std::size_t>(h)];
        break;
    }
  }
  // The grid of values is the tensor collocation matrix times the coefficients; its
  // least-squares inverse is the tensor product of the per-direction inverses.
  for (int d = 0; d < P; ++d) {
    const auto dd = static_cast<std::size_t>(d);
    net = solve_along<P>(net, d, knots[dd], samples[dd]);
  }
  return detail::from_net<P>(std::move(knots), dim, false, std::move(net));
}

template <int P>
TensorSpline<P> add(const TensorSpline<P>& a, const TensorSpline<P>& b, double scale) {
  if (a.dim() != b.dim())
    throw Error("sum of splines with " + std::to_string(a.dim()) + " and " + std::to_string(b.dim()) +
                " coordinates; expected equal counts");
  require_polynomial(a, "sum");
  require_polynomial(b, "sum");
  auto [x, y] = make_compatible(a, b);
  auto pts = x.points();
  const auto q = y.points();
  for (std::size_t i = 0; i < pts.size(); ++i) pts[i] += scale * q[i];
  return x;
}

template <int P>
TensorSpline<P> coordinates(const TensorSpline<P>& s, int first, int count) {
  if (first < 0 || count < 1 || first + count > s.dim())
    throw Error("coordinates [" + std::to_string(first) + ", " + std::to_string(first + count) + ") of a spline with " +
                std::to_string(s.dim()) + "; expected a range inside 0.." + std::to_string(s.dim()));
  std::vector<double> pts(static_cast<std::size_t>(s.size() * count));
  for (int r = 0; r < s.size(); ++r)
    for (int h = 0; h < count; ++h)
      pts[static_cast<std::size_t>(r * count + h)] = s.point(r)[static_cast<std::size_t>(first + h)];
  return TensorSpline<P>(s.knot_vectors(), count, std::move(pts), s.weights());
}

Trivariate jacobian_determinant(const Trivariate& s) {
  require_polynomial(s, "Jacobian determinant");
  if (s.dim() < 3) throw Error("Jacobian determinant of a trivariate in R^" + std::to_string(s.dim()) + "; expected xyz");
  const Trivariate x = coordinates(s, 0, 3);
  const Trivariate du = derivative(x, 0), dv = derivative(x, 1), dw = derivative(x, 2);
  return product(du, product(dv, dw, ProductKind::cross), ProductKind::dot);
}

Surface jacobian_determinant(const Surface& s) {
  require_polynomial(s, "Jacobian determinant");
  if (s.dim() < 2) throw Error("Jacobian determinant of a surface in R^" + std::to_string(s.dim()) + "; expected xy");
  const Surface x = coordinates(s, 0, 1), y = coordinates(s, 1, 1);
  return add(product(derivative(x, 0), derivative(y, 1), ProductKind::scalar),
             product(derivative(x, 1), derivative(y, 0), ProductKind::scalar), -1.0);
}

#define TRIVOX_INSTANTIATE(P)                                                                        \
  template TensorSpline<P> derivative(const TensorSpline<P>&, int);                                  \
  template TensorSpline<P> product(const TensorSpline<P>&, const TensorSpline<P>&, ProductKind);     \
  template TensorSpline<P> add(const TensorSpline<P>&, const TensorSpline<P>&, double);              \
  template TensorSpline<P> coordinates(const TensorSpline<P>&, int, int);
TRIVOX_INSTANTIATE(1)
TRIVOX_INSTANTIATE(2)
TRIVOX_INSTANTIATE(3)
#undef TRIVOX_INSTANTIATE

}  // namespace trivox::spline
