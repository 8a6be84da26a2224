#include "patch_quadrature.hpp"

#include <algorithm>

#include "trivox/geom/quadrature.hpp"

namespace trivox::geom::detail {

const BernsteinRule& PatchRules::get(int order, int points) {
  const auto key = std::make_pair(order, points);
  if (const auto it = rules_.find(key); it != rules_.end()) return it->second;
  const GaussRule g = gauss_legendre(points);
  BernsteinRule r;
  const int p = order - 1;
  const auto o = static_cast<std::size_t>(order);
  for (std::size_t q = 0; q < g.nodes.size(); ++q) {
    const double t = 0.5 * (1 + g.nodes[q]);
    r.nodes.push_back(t);
    r.weights.push_back(0.5 * g.weights[q]);
    // B_i^d from B^(d-1) by the triangle; B_i^p' = p (B_(i-1)^(p-1) - B_i^(p-1)).
    std::vector<double> b(o, 0.0), lower(o, 0.0);
    b[0] = 1;
    for (int d = 1; d <= p; ++d) {
      if (d == p) lower = b;
      for (int i = d; i >= 0; --i) {
        const auto u = static_cast<std::size_t>(i);
        b[u] = (i < d ? (1 - t) * b[u] : 0.0) + (i > 0 ? t * b[u - 1] : 0.0);
      }
    }
    for (std::size_t i = 0; i < o; ++i) {
      r.b.push_back(b[i]);
      const double left = i > 0 ? lower[i - 1] : 0.0, right = static_cast<int>(i) < p ? lower[i] : 0.0;
      r.db.push_back(p * (left - right));
    }
  }
  return rules_.emplace(key, std::move(r)).first->second;
}

void bezier_points(const spline::Surface& p, int ns, int nt, PatchRules& rules, std::vector<PatchPoint>& out) {
  const auto os = static_cast<std::size_t>(p.orders()[0]), ot = static_cast<std::size_t>(p.orders()[1]);
  const auto dim = static_cast<std::size_t>(p.dim());
  const BernsteinRule& rs = rules.get(static_cast<int>(os), ns);
  const BernsteinRule& rt = rules.get(static_cast<int>(ot), nt);
  const auto pts = p.points();
  std::vector<double> q0(3 * os), q1(3 * os);
  out.reserve(rs.nodes.size() * rt.nodes.size());
  for (std::size_t j = 0; j < rt.nodes.size(); ++j) {
    std::fill(q0.begin(), q0.end(), 0.0);
    std::fill(q1.begin(), q1.end(), 0.0);
    for (std::size_t l = 0; l < ot; ++l) {
      const double b = rt.b[j * ot + l], db = rt.db[j * ot + l];
      for (std::size_t i = 0; i < os; ++i)
        for (std::size_t k = 0; k < 3; ++k) {
          const double v = pts[(i + os * l) * dim + k];
          q0[3 * i + k] += b * v;
          q1[3 * i + k] += db * v;
        }
    }
    for (std::size_t i = 0; i < rs.nodes.size(); ++i) {
      PatchPoint pt{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, rs.weights[i] * rt.weights[j]};
      for (std::size_t a = 0; a < os; ++a) {
        const double b = rs.b[i * os + a], db = rs.db[i * os + a];
        for (std::size_t k = 0; k < 3; ++k) {
          pt.x[k] += b * q0[3 * a + k];
          pt.xs[k] += db * q0[3 * a + k];
          pt.xt[k] += b * q1[3 * a + k];
        }
      }
      out.push_back(pt);
    }
  }
}

void spline_points(const spline::Surface& p, int ns, int nt, std::vector<PatchPoint>& out) {
  const GaussRule gs = gauss_legendre(ns), gt = gauss_legendre(nt);
  const auto dim = static_cast<std::size_t>(p.dim());
  std::vector<double> d(3 * dim);
  auto spans = [](const spline::KnotVector& k) {
    std::vector<std::array<double, 2>> s;
    const auto& t = k.knots();
    for (std::size_t i = 0; i + 1 < t.size(); ++i)
      if (t[i + 1] > t[i]) s.push_back({t[i], t[i + 1]});
    return s;
  };
  for (const auto& a : spans(p.knots(0)))
    for (const auto& b : spans(p.knots(1))) {
      const double hs = 0.5 * (a[1] - a[0]), ht = 0.5 * (b[1] - b[0]);
      for (std::size_t j = 0; j < gt.nodes.size(); ++j)
        for (std::size_t i = 0; i < gs.nodes.size(); ++i) {
          p.eval_derivatives({a[0] + hs * (1 + gs.nodes[i]), b[0] + ht * (1 + gt.nodes[j])}, 1, d.data());
          PatchPoint pt;
          for (std::size_t k = 0; k < 3; ++k) pt.x[k] = d[k], pt.xs[k] = d[dim + k], pt.xt[k] = d[2 * dim + k];
          pt.w = gs.weights[i] * gt.weights[j] * hs * ht;
          out.push_back(pt);
        }
    }
}

}  // namespace trivox::geom::detail
