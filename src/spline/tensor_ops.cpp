#include "tensor_ops.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "trivox/error.hpp"

namespace trivox::spline::detail {

template <int P>
Net<P> to_net(const TensorSpline<P>& s) {
  Net<P> net;
  net.extents = s.counts();
  const int dim = s.dim();
  net.H = dim + (s.rational() ? 1 : 0);
  net.values.resize(static_cast<std::size_t>(s.size()) * static_cast<std::size_t>(net.H));
  for (int r = 0; r < s.size(); ++r) {
    const auto p = s.point(r);
    double* o = net.values.data() + static_cast<std::ptrdiff_t>(r) * net.H;
    const double w = s.rational() ? s.weights()[static_cast<std::size_t>(r)] : 1.0;
    for (int h = 0; h < dim; ++h) o[h] = w * p[static_cast<std::size_t>(h)];
    if (s.rational()) o[dim] = w;
  }
  return net;
}

template <int P>
TensorSpline<P> from_net(std::array<KnotVector, P> knots, int dim, bool rational, Net<P> net) {
  std::size_t n = 1;
  for (int d = 0; d < P; ++d) n *= static_cast<std::size_t>(net.extents[static_cast<std::size_t>(d)]);
  if (!rational) return TensorSpline<P>(std::move(knots), dim, std::move(net.values));
  std::vector<double> pts(n * static_cast<std::size_t>(dim)), w(n);
  for (std::size_t r = 0; r < n; ++r) {
    const double* q = net.values.data() + r * static_cast<std::size_t>(net.H);
    w[r] = q[dim];
    for (int h = 0; h < dim; ++h) pts[r * static_cast<std::size_t>(dim) + static_cast<std::size_t>(h)] = q[h] / q[dim];
  }
  return TensorSpline<P>(std::move(knots), dim, std::move(pts), std::move(w));
}

template <int P>
Net<P> apply_along(const Net<P>& net, int d, const Eigen::MatrixXd& T) {
  // Transfer matrices are banded (refinement, elevation, restriction: a few non-zeros per row):
  // each row's non-zero columns are found once, not once per line of the net.
  return apply_along(net, d, Banded::from_dense(T));
}

std::vector<double> span_samples(const KnotVector& kv, int k) {
  std::vector<double> out;
  const auto& t = kv.knots();
  for (int mu = kv.order() - 1; mu < kv.size(); ++mu) {
    const double a = t[static_cast<std::size_t>(mu)], b = t[static_cast<std::size_t>(mu) + 1];
    if (!(a < b)) continue;
    for (int i = 0; i < k; ++i) {
      const double x = std::cos(std::numbers::pi * (2.0 * i + 1.0) / (2.0 * k));  // in (-1, 1)
      out.push_back(0.5 * (a + b) + 0.5 * (b - a) * x);
    }
  }
  return out;
}

Eigen::MatrixXd collocation(const KnotVector& kv, const std::vector<double>& samples) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(samples.size()), kv.size());
  std::vector<double> N(static_cast<std::size_t>(kv.order()));
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const int mu = kv.find_span(samples[i]);
    kv.basis(mu, samples[i], N.data());
    for (int j = 0; j < kv.order(); ++j) A(static_cast<Eigen::Index>(i), mu - kv.order() + 1 + j) = N[static_cast<std::size_t>(j)];
  }
  return A;
}

Eigen::MatrixXd basis_row(const KnotVector& kv, double t) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(1, kv.size());
  std::vector<double> N(static_cast<std::size_t>(kv.order()));
  const int mu = kv.find_span(t);
  kv.basis(mu, std::clamp(t, kv.front(), kv.back()), N.data());
  for (int j = 0; j < kv.order(); ++j) A(0, mu - kv.order() + 1 + j) = N[static_cast<std::size_t>(j)];
  return A;
}

KnotVector with_knots(const KnotVector& kv, std::vector<double> add) {
  std::vector<double> k = kv.knots();
  k.insert(k.end(), add.begin(), add.end());
  std::sort(k.begin(), k.end());
  return KnotVector(kv.order(), std::move(k));
}

Eigen::MatrixXd transfer_matrix(const KnotVector& from, const KnotVector& to) {
  if (from.front() != to.front() || from.back() != to.back())
    throw Error("function spaces on different domains [" + std::to_string(from.front()) + ", " +
                std::to_string(from.back()) + "] and [" + std::to_string(to.front()) + ", " +
                std::to_string(to.back()) + "]; expected the same domain");
  if (to.order() < from.order())
    throw Error("order " + std::to_string(to.order()) + " cannot hold order " + std::to_string(from.order()) +
                "; expected a target order >= the source order");
  // Column j of T expresses the source's basis function B_j in the target basis. B_j vanishes
  // outside its support [a, b], and so (local linear independence of B-splines) it is a
  // combination of the target functions whose supports lie in [a, b]: a small collocation
  // system on the target's spans inside [a, b], one per source function. Cost O(n_from *
  // (local size)^3) instead of a dense solve of the whole space.
  const int nf = from.size(), nt = to.size(), kf = from.order(), kt = to.order();
  const auto& tf = from.knots();
  const auto& tt = to.knots();
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(nt, nf);
  std::vector<double> N(static_cast<std::size_t>(std::max(kf, kt)));
  const double eps = 1e-13 * (to.back() - to.front());
  double residual = 0.0;
  for (int j = 0; j < nf; ++j) {
    const double a = std::max(tf[static_cast<std::size_t>(j)], from.front());
    const double b = std::min(tf[static_cast<std::size_t>(j + kf)], from.back());
    if (!(a < b)) continue;
    // Target functions i with a <= t_i and t_{i+kt} <= b; target spans inside [a, b].
    int i0 = 0;
    while (i0 < nt && tt[static_cast<std::size_t>(i0)] < a - eps) ++i0;
    int i1 = nt - 1;
    while (i1 >= 0 && tt[static_cast<std::size_t>(i1 + kt)] > b + eps) --i1;
    std::vector<double> samples;
    for (int mu = kt - 1; mu < nt; ++mu) {
      const double lo = tt[static_cast<std::size_t>(mu)], hi = tt[static_cast<std::size_t>(mu) + 1];
      if (!(lo < hi) || lo < a - eps || hi > b + eps) continue;
      for (int r = 0; r < kt; ++r) {
        const double x = std::cos(std::numbers::pi * (2.0 * r + 1.0) / (2.0 * kt));
        samples.push_back(0.5 * (lo + hi) + 0.5 * (hi - lo) * x);
      }
    }
    const int cols = i1 - i0 + 1;
    if (cols <= 0 || samples.empty()) {
      residual = 1.0;  // no target function fits inside B_j's support: not a refinement
      break;
    }
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(samples.size()), cols);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(samples.size()));
    for (std::size_t r = 0; r < samples.size(); ++r) {
      const double x = samples[r];
      const int mt = to.find_span(x);
      to.basis(mt, x, N.data());
      for (int c = 0; c < kt; ++c) {
        const int i = mt - kt + 1 + c;
        if (i >= i0 && i <= i1) A(static_cast<Eigen::Index>(r), i - i0) = N[static_cast<std::size_t>(c)];
      }
      const int mf = from.find_span(x);
      from.basis(mf, x, N.data());
      const int c = j - (mf - kf + 1);
      if (c >= 0 && c < kf) rhs(static_cast<Eigen::Index>(r)) = N[static_cast<std::size_t>(c)];
    }
    const Eigen::VectorXd x = A.colPivHouseholderQr().solve(rhs);
    residual = std::max(residual, (A * x - rhs).cwiseAbs().maxCoeff());
    T.block(i0, j, cols, 1) = x;
  }
  // The systems are consistent exactly when `to` contains `from`.
  if (!(residual < 1e-9))
    throw Error("the target function space does not contain the source (collocation residual " +
                std::to_string(residual) + "); expected a refinement or elevation of the source knots");
  return T;
}

KnotVector merged_space(const KnotVector& ka, const KnotVector& kb, int order) {
  const auto ba = ka.breakpoints(), bb = kb.breakpoints();
  std::vector<Breakpoint> br;
  std::size_t i = 0, j = 0;
  while (i < ba.size() || j < bb.size()) {
    const bool take_a = j >= bb.size() || (i < ba.size() && ba[i].value <= bb[j].value);
    const bool take_b = i >= ba.size() || (j < bb.size() && bb[j].value <= ba[i].value);
    const double v = take_a ? ba[i].value : bb[j].value;
    int cont = order;  // a value that is no knot of a factor is as smooth as can be there
    if (take_a) cont = std::min(cont, ka.degree() - ba[i++].multiplicity);
    if (take_b) cont = std::min(cont, kb.degree() - bb[j++].multiplicity);
    br.push_back({v, std::clamp(order - 1 - cont, 0, order)});
  }
  return KnotVector::from_breakpoints(order, br);
}

template struct Net<1>;
template struct Net<2>;
template struct Net<3>;
template Net<1> to_net(const TensorSpline<1>&);
template Net<2> to_net(const TensorSpline<2>&);
template Net<3> to_net(const TensorSpline<3>&);
template TensorSpline<1> from_net<1>(std::array<KnotVector, 1>, int, bool, Net<1>);
template TensorSpline<2> from_net<2>(std::array<KnotVector, 2>, int, bool, Net<2>);
template TensorSpline<3> from_net<3>(std::array<KnotVector, 3>, int, bool, Net<3>);

Banded Banded::identity(int n) {
  Banded b;
  b.cols = n;
  const double one = 1.0;
  for (int i = 0; i < n; ++i) b.push_row(i, &one, 1);
  return b;
}

Banded Banded::from_dense(const Eigen::MatrixXd& T) {
  Banded b;
  b.cols = static_cast<int>(T.cols());
  const auto m = static_cast<std::size_t>(T.rows());
  // Each row's first and last non-zero column, in one sweep in storage order (column-major).
  std::vector<Eigen::Index> lo(m, T.cols()), hi(m, -1);
  for (Eigen::Index i = 0; i < T.cols(); ++i)
    for (Eigen::Index j = 0; j < T.rows(); ++j)
      if (T(j, i) != 0.0) {
        const auto uj = static_cast<std::size_t>(j);
        lo[uj] = std::min(lo[uj], i);
        hi[uj] = std::max(hi[uj], i);
      }
  std::vector<double> row;
  for (std::size_t j = 0; j < m; ++j) {
    row.clear();
    for (Eigen::Index i = lo[j]; i <= hi[j]; ++i) row.push_back(T(static_cast<Eigen::Index>(j), i));
    b.push_row(hi[j] >= lo[j] ? static_cast<int>(lo[j]) : 0, row.data(), row.size());
  }
  return b;
}

Eigen::MatrixXd Banded::dense() const {
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(rows(), cols);
  for (int j = 0; j < rows(); ++j)
    for (std::size_t k = start[static_cast<std::size_t>(j)]; k < start[static_cast<std::size_t>(j) + 1]; ++k)
      T(j, first[static_cast<std::size_t>(j)] + static_cast<Eigen::Index>(k - start[static_cast<std::size_t>(j)])) = vals[k];
  return T;
}

Banded Banded::middle_rows(int from, int count) const {
  Banded b;
  b.cols = cols;
  for (int j = from; j < from + count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    b.push_row(first[uj], vals.data() + start[uj], start[uj + 1] - start[uj]);
  }
  return b;
}

template <int P>
Net<P> apply_along(const Net<P>& net, int d, const Banded& T) {
  const auto dd = static_cast<std::size_t>(d);
  const int n = net.extents[dd];
  const int m = T.rows();
  if (T.cols != n) throw Error("internal: transfer matrix has " + std::to_string(T.cols) + " columns; expected " + std::to_string(n));
  for (int j = 0; j < m; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const auto len = static_cast<std::ptrdiff_t>(T.start[uj + 1] - T.start[uj]);
    if (len > 0 && (T.first[uj] < 0 || T.first[uj] + len > n))
      throw Error("internal: banded transfer row " + std::to_string(j) + " reaches beyond column " + std::to_string(n - 1));
  }
  std::ptrdiff_t inner = 1, outer = 1;
  for (int e = 0; e < d; ++e) inner *= net.extents[static_cast<std::size_t>(e)];
  for (int e = d + 1; e < P; ++e) outer *= net.extents[static_cast<std::size_t>(e)];
  Net<P> out;
  out.extents = net.extents;
  out.extents[dd] = m;
  out.H = net.H;
  const std::ptrdiff_t H = net.H;
  out.values.assign(static_cast<std::size_t>(outer * m * inner * H), 0.0);
  for (std::ptrdiff_t o = 0; o < outer; ++o) {
    const double* src = net.values.data() + o * n * inner * H;
    double* dst = out.values.data() + o * m * inner * H;
    for (int j = 0; j < m; ++j) {
      double* drow = dst + j * inner * H;
      const auto uj = static_cast<std::size_t>(j);
      for (std::size_t k = T.start[uj]; k < T.start[uj + 1]; ++k) {
        const double c = T.vals[k];
        if (c == 0.0) continue;
        const int i = T.first[uj] + static_cast<int>(k - T.start[uj]);
        const double* srow = src + i * inner * H;
        for (std::ptrdiff_t q = 0; q < inner * H; ++q) drow[q] += c * srow[q];
      }
    }
  }
  return out;
}

template Net<1> apply_along(const Net<1>&, int, const Banded&);
template Net<2> apply_along(const Net<2>&, int, const Banded&);
template Net<3> apply_along(const Net<3>&, int, const Banded&);
template Net<1> apply_along(const Net<1>&, int, const Eigen::MatrixXd&);
template Net<2> apply_along(const Net<2>&, int, const Eigen::MatrixXd&);
template Net<3> apply_along(const Net<3>&, int, const Eigen::MatrixXd&);

}  // namespace trivox::spline::detail
