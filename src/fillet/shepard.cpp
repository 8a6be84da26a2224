#include "trivox/fillet/shepard.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include "trivox/error.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::fillet {

namespace {

/// A dense row-major matrix.
struct Matrix {
  int rows = 0, cols = 0;
  std::vector<double> a;
  Matrix(int r, int c) : rows(r), cols(c), a(static_cast<std::size_t>(r) * static_cast<std::size_t>(c), 0.0) {}
  double& operator()(int i, int j) { return a[static_cast<std::size_t>(i) * static_cast<std::size_t>(cols) + static_cast<std::size_t>(j)]; }
  double operator()(int i, int j) const { return a[static_cast<std::size_t>(i) * static_cast<std::size_t>(cols) + static_cast<std::size_t>(j)]; }
};

/// The fit space along u or v: the half's own for few control points, else order <= 4 on at
/// most max_spans of its breakpoints, multiplicities lowered with the order so that the space
/// elevated to the half's order lies in the half's (where the half is smooth enough to allow it).
spline::KnotVector fit_space(const spline::KnotVector& kv, const ShepardOptions& opt, bool graded) {
  if (kv.size() <= opt.max_direct) {
    if (!graded || opt.grade < 1) return kv;
    // Across C (v): f turns from g_1 to g_2 around C within a small angle near it, so knots
    // graded towards both ends of v (C is at one, the rail at the other): 1/2, 2^-k, 1 - 2^-k.
    const double a = kv.front(), b = kv.back();
    std::vector<double> add{0.5};
    for (int k = 2; k <= opt.grade + 1; ++k) add.insert(add.end(), {std::ldexp(1.0, -k), 1.0 - std::ldexp(1.0, -k)});
    std::vector<double> t = kv.knots();
    for (double x : add)
      if (kv.multiplicity(a + x * (b - a)) == 0) t.push_back(a + x * (b - a));
    std::sort(t.begin(), t.end());
    return spline::KnotVector(kv.order(), t);
  }
  const int o = kv.order(), oc = std::min(4, o);
  const auto br = kv.breakpoints();
  const int spans = static_cast<int>(br.size()) - 1;
  const int stride = (spans + opt.max_spans - 1) / opt.max_spans;
  std::vector<spline::Breakpoint> keep{br.front()};
  for (int s = stride; s < spans; s += stride) {
    const int mult = std::clamp(br[static_cast<std::size_t>(s)].multiplicity - (o - oc), 1, oc - 1);
    keep.push_back({br[static_cast<std::size_t>(s)].value, mult});
  }
  keep.push_back(br.back());
  return spline::KnotVector::from_breakpoints(oc, keep);
}

/// Gauss points per non-empty span: twice the functions per span (at least 2, at most order + 1),
/// so every function's support holds several samples and the fit is well posed.
std::vector<double> samples(const spline::KnotVector& kv) {
  const auto br = kv.breakpoints();
  const int spans = static_cast<int>(br.size()) - 1;
  const int per = std::clamp((2 * kv.size() + spans - 1) / spans, 2, kv.order() + 1);
  const auto g = geom::gauss_legendre(per);
  std::vector<double> t;
  for (std::size_t s = 0; s + 1 < br.size(); ++s) {
    const double a = br[s].value, b = br[s + 1].value;
    for (double x : g.nodes) t.push_back(a + 0.5 * (x + 1.0) * (b - a));
  }
  return t;
}

/// (B^T B)^-1 B^T for the collocation matrix B of kv at t, without the first `skip` columns.
Matrix pseudo_inverse(const spline::KnotVector& kv, const std::vector<double>& t, int skip) {
  const int n = kv.size() - skip, ns = static_cast<int>(t.size()), o = kv.order();
  Matrix B(ns, n);
  std::vector<double> N(static_cast<std::size_t>(o));
  for (int r = 0; r < ns; ++r) {
    const int span = kv.find_span(t[static_cast<std::size_t>(r)]);
    kv.basis(span, t[static_cast<std::size_t>(r)], N.data());
    for (int k = 0; k < o; ++k) {
      const int col = span - o + 1 + k - skip;
      if (col >= 0) B(r, col) = N[static_cast<std::size_t>(k)];
    }
  }
  // Normal equations, Cholesky (B has full column rank: Gauss points per span).
  Matrix A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j <= i; ++j) {
      double s = 0.0;
      for (int r = 0; r < ns; ++r) s += B(r, i) * B(r, j);
      A(i, j) = A(j, i) = s;
    }
  for (int j = 0; j < n; ++j) {
    double d = A(j, j);
    for (int k = 0; k < j; ++k) d -= A(j, k) * A(j, k);
    if (!(d > 0)) throw Error("Shepard encoding: the fit space's normal equations are singular", ErrorKind::failed);
    A(j, j) = std::sqrt(d);
    for (int i = j + 1; i < n; ++i) {
      double s = A(i, j);
      for (int k = 0; k < j; ++k) s -= A(i, k) * A(j, k);
      A(i, j) = s / A(j, j);
    }
  }
  Matrix P(n, ns);  // solve L L^T P = B^T, column by column
  std::vector<double> x(static_cast<std::size_t>(n));
  for (int r = 0; r < ns; ++r) {
    for (int i = 0; i < n; ++i) {
      double s = B(r, i);
      for (int k = 0; k < i; ++k) s -= A(i, k) * x[static_cast<std::size_t>(k)];
      x[static_cast<std::size_t>(i)] = s / A(i, i);
    }
    for (int i = n - 1; i >= 0; --i) {
      double s = x[static_cast<std::size_t>(i)];
      for (int k = i + 1; k < n; ++k) s -= A(k, i) * x[static_cast<std::size_t>(k)];
      x[static_cast<std::size_t>(i)] = s / A(i, i);
    }
    for (int i = 0; i < n; ++i) P(i, r) = x[static_cast<std::size_t>(i)];
  }
  return P;
}

/// data[x0][x1][x2][h] (x0 slowest) times P along `axis`: that extent becomes P.rows.
std::vector<double> mode_product(const std::vector<double>& data, std::array<int, 3>& dims, int m, int axis, const Matrix& P) {
  std::array<int, 3> nd = dims;
  nd[static_cast<std::size_t>(axis)] = P.rows;
  std::vector<double> out(static_cast<std::size_t>(nd[0]) * nd[1] * nd[2] * m, 0.0);
  const auto at = [m](const std::array<int, 3>& d, int i0, int i1, int i2) {
    return ((static_cast<std::size_t>(i0) * d[1] + i1) * d[2] + i2) * static_cast<std::size_t>(m);
  };
  for (int i0 = 0; i0 < nd[0]; ++i0)
    for (int i1 = 0; i1 < nd[1]; ++i1)
      for (int i2 = 0; i2 < nd[2]; ++i2) {
        double* o = out.data() + at(nd, i0, i1, i2);
        const int row = axis == 0 ? i0 : axis == 1 ? i1 : i2;
        for (int c = 0; c < P.cols; ++c) {
          const double w = P(row, c);
          if (w == 0.0) continue;
          const int j0 = axis == 0 ? c : i0, j1 = axis == 1 ? c : i1, j2 = axis == 2 ? c : i2;
          const double* s = data.data() + at(dims, j0, j1, j2);
          for (int h = 0; h < m; ++h) o[h] += w * s[h];
        }
      }
  dims = nd;
  return out;
}

}  // namespace

ShepardEncoding encode_shepard(const spline::Trivariate& half, const vmodel::ShepardField& field, const ShepardOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  const int m = field.properties(), dim = 3 + m;
  if (half.dim() != dim)
    throw Error("Shepard encoding: the half has " + std::to_string(half.dim()) + " coordinates; expected " +
                std::to_string(dim) + " (xyz and the Shepard surfaces' properties)");
  if (half.rational()) throw Error("Shepard encoding: the half is rational; expected a polynomial fillet half");
  if (opt.w_spans < 1 || opt.w_spans > 16 || opt.w_order < 2 || opt.w_order > 8 || opt.max_spans < 1 || opt.max_direct < 1)
    throw Error("Shepard encoding: options out of range (w_spans 1..16, w_order 2..8, max_spans and max_direct >= 1)");
  ShepardEncoding out;
  if (m == 0) {
    out.half = half;
    return out;
  }
  const auto dw = half.domain(2);
  // Along w: breakpoints graded towards S^_i (w = 0), where f changes fastest near C.
  std::vector<spline::Breakpoint> wb{{dw[0], opt.w_order}};
  for (int k = opt.w_spans - 1; k >= 1; --k) wb.push_back({dw[0] + std::ldexp(1.0, -k) * (dw[1] - dw[0]), 1});
  wb.push_back({dw[1], opt.w_order});
  const std::array<spline::KnotVector, 3> fk{fit_space(half.knots(0), opt, false), fit_space(half.knots(1), opt, true),
                                             spline::KnotVector::from_breakpoints(opt.w_order, wb)};
  const std::array<std::vector<double>, 3> s{samples(fk[0]), samples(fk[1]), samples(fk[2])};
  const std::array<int, 3> ns{static_cast<int>(s[0].size()), static_cast<int>(s[1].size()), static_cast<int>(s[2].size())};
  // f and G (the half's own properties on w = 0) at every sample; one walk per u sample, cold
  // at its start: the values do not depend on the thread count.
  const std::size_t total = static_cast<std::size_t>(ns[0]) * ns[1] * ns[2];
  std::vector<double> f(total * m), r(total * m);
  tbb::parallel_for(0, ns[0], [&](int a) {
    vmodel::ShepardWalk walk;
    std::vector<double> x(static_cast<std::size_t>(dim)), g(static_cast<std::size_t>(dim));
    for (int b = 0; b < ns[1]; ++b) {
      half.eval({s[0][a], s[1][b], dw[0]}, g.data());
      for (int cc = 0; cc < ns[2]; ++cc) {
        const int c = b % 2 == 0 ? cc : ns[2] - 1 - cc;  // serpentine: neighbours stay close
        const std::size_t at = ((static_cast<std::size_t>(a) * ns[1] + b) * ns[2] + c) * m;
        half.eval({s[0][a], s[1][b], s[2][c]}, x.data());
        field.eval({x[0], x[1], x[2]}, f.data() + at, &walk);
        for (int h = 0; h < m; ++h) r[at + h] = f[at + h] - g[static_cast<std::size_t>(3 + h)];
      }
    }
  });
  out.samples = static_cast<std::int64_t>(total);
  // Least squares on the tensor grid: the Kronecker product of the 1-D pseudo-inverses; R's
  // first layer along w (the face w = 0) is pinned to zero.
  std::array<int, 3> dims = ns;
  std::vector<double> c = mode_product(r, dims, m, 0, pseudo_inverse(fk[0], s[0], 0));
  c = mode_product(c, dims, m, 1, pseudo_inverse(fk[1], s[1], 0));
  c = mode_product(c, dims, m, 2, pseudo_inverse(fk[2], s[2], 1));
  const int nu = fk[0].size(), nv = fk[1].size(), nw = fk[2].size();
  std::vector<double> pts(static_cast<std::size_t>(nu) * nv * nw * m, 0.0);
  for (int k = 1; k < nw; ++k)
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nu; ++i)
        for (int h = 0; h < m; ++h)
          pts[(static_cast<std::size_t>(i) + static_cast<std::size_t>(nu) * (j + static_cast<std::size_t>(nv) * k)) * m + h] =
              c[((static_cast<std::size_t>(i) * nv + j) * (nw - 1) + (k - 1)) * m + h];
  out.fit_counts = {nu, nv, nw};
  const spline::Trivariate R(fk, m, std::move(pts));
  auto [H, Rc] = spline::make_compatible(half, R);
  // Properties G + R; the face w = 0 (xyz and properties) is the half's own, bit for bit, when
  // its u and v spaces are unchanged (the usual case), else the compatible half's.
  const bool same_uv = H.knots(0) == half.knots(0) && H.knots(1) == half.knots(1);
  const int hu = H.count(0), hv = H.count(1), hw = H.count(2);
  for (int j = 0; j < hv; ++j)
    for (int i = 0; i < hu; ++i) {
      std::vector<double> base(static_cast<std::size_t>(dim));
      const auto b0 = same_uv ? half.point(half.row({i, j, 0})) : H.point(H.row({i, j, 0}));
      std::copy(b0.begin(), b0.end(), base.begin());
      for (int k = 0; k < hw; ++k) {
        auto p = H.point(H.row({i, j, k}));
        if (k == 0) {
          std::copy(base.begin(), base.end(), p.begin());
          continue;
        }
        const auto rr = Rc.point(Rc.row({i, j, k}));
        for (int h = 0; h < m; ++h) p[static_cast<std::size_t>(3 + h)] = base[static_cast<std::size_t>(3 + h)] + rr[static_cast<std::size_t>(h)];
      }
    }
  // Errors at the samples and at midpoints between them.
  double se = 0.0, me = 0.0;
  std::vector<double> x(static_cast<std::size_t>(dim));
  for (int a = 0; a < ns[0]; ++a)
    for (int b = 0; b < ns[1]; ++b)
      for (int cc = 0; cc < ns[2]; ++cc) {
        const std::size_t at = ((static_cast<std::size_t>(a) * ns[1] + b) * ns[2] + cc) * m;
        H.eval({s[0][a], s[1][b], s[2][cc]}, x.data());
        for (int h = 0; h < m; ++h) {
          const double e = std::abs(x[static_cast<std::size_t>(3 + h)] - f[at + h]);
          me = std::max(me, e);
          se += e * e;
        }
      }
  out.max_error = me;
  out.rms_error = std::sqrt(se / static_cast<double>(total * m));
  const auto mid = [](const std::vector<double>& t, int k) { return 0.5 * (t[static_cast<std::size_t>(k)] + t[static_cast<std::size_t>(k) + 1]); };
  std::vector<double> check(static_cast<std::size_t>(std::max(0, ns[0] - 1)), 0.0);
  // H captured by name: clang before version 16 cannot capture a structured binding.
  tbb::parallel_for(0, ns[0] - 1, [&, &H = H](int a) {
    vmodel::ShepardWalk walk;
    std::vector<double> y(static_cast<std::size_t>(dim)), fv(static_cast<std::size_t>(m));
    double e = 0.0;
    for (int b = 0; b + 1 < ns[1]; ++b)
      for (int cc = 0; cc + 1 < ns[2]; ++cc) {
        const int c = b % 2 == 0 ? cc : ns[2] - 2 - cc;
        H.eval({mid(s[0], a), mid(s[1], b), mid(s[2], c)}, y.data());
        field.eval({y[0], y[1], y[2]}, fv.data(), &walk);
        for (int h = 0; h < m; ++h) e = std::max(e, std::abs(y[static_cast<std::size_t>(3 + h)] - fv[static_cast<std::size_t>(h)]));
      }
    check[static_cast<std::size_t>(a)] = e;
  });
  for (double e : check) out.check_error = std::max(out.check_error, e);
  out.half = std::move(H);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace trivox::fillet
