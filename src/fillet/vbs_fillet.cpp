#include "trivox/fillet/vbs_fillet.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "property_blend.hpp"
#include "trivox/construct/constructors.hpp"
#include "fillet_util.hpp"
#include "trivox/error.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::fillet {

using spline::Curve;
using spline::KnotVector;
using spline::Surface;
using spline::Trivariate;
using detail::curve_gap;
using detail::num;
using detail::project;
using detail::row;
using detail::set_row;
using detail::xyz_at;
using detail::knot_merge;
using detail::merge_close_knots;
using detail::split_across;

namespace {

/// One cell: the volumetric Boolean sum of its sleeve (faces v0, v1, w0, w1, all in U x X) and
/// the Coons caps of the sleeve's end curves. With Coons caps the six-face sum
/// Pu + Pv + Pw - Puv - Puw - Pvw + Puvw loses its u terms (for each end a, the u-face minus
/// the Coons patch of its own boundary is zero), leaving, at every u, the Coons patch of the
/// cross-section's four curves: T = Pv + Pw - Pvw. That is built here directly in U x X x X,
/// the linear blends (1 - v, v) written in X with its Greville abscissae (linear precision), so
/// U is never converted (construct::boolean_sum of the same six faces gives the same cell, but
/// converts order-2 blends into U: tens of seconds for a thousand control points along C).
/// Each edge along u is the mean of its two faces' rows (the one curve when they agree); the
/// boundary layers are then set to the faces' control points and the edges to these means.
Trivariate cell(const Surface& v0, const Surface& v1, const Surface& w0, const Surface& w1) {
  const KnotVector &U = v0.knots(0), &X = v0.knots(1);
  for (const Surface* f : {&v1, &w0, &w1})
    if (f->knots(0) != U || f->knots(1) != X)
      throw Error("VBS fillet: the sleeve surfaces are in different function spaces (internal)", ErrorKind::failed);
  const int nu = U.size(), nx = X.size(), k = v0.dim();
  const std::size_t kk = static_cast<std::size_t>(k);
  std::vector<double> g(static_cast<std::size_t>(nx));  // Greville abscissae: sum g_j N_j(t) = t
  for (int j = 0; j < nx; ++j) {
    double sum = 0.0;
    for (int q = 1; q < X.order(); ++q) sum += X[j + q];
    g[static_cast<std::size_t>(j)] = sum / (X.order() - 1);
  }
  // Edges along u at (v, w) = (a, b): E[a][b], control points in U.
  const auto mean_row = [&](const Surface& f, int jf, const Surface& h, int jh) {
    std::vector<double> e(static_cast<std::size_t>(nu) * kk);
    for (int i = 0; i < nu; ++i) {
      const auto x = f.point(f.row({i, jf})), y = h.point(h.row({i, jh}));
      for (std::size_t c = 0; c < kk; ++c) e[static_cast<std::size_t>(i) * kk + c] = x[c] == y[c] ? x[c] : 0.5 * (x[c] + y[c]);
    }
    return e;
  };
  const std::vector<double> E[2][2] = {{mean_row(v0, 0, w0, 0), mean_row(v0, nx - 1, w1, 0)},
                                       {mean_row(v1, 0, w0, nx - 1), mean_row(v1, nx - 1, w1, nx - 1)}};
  Trivariate t({U, X, X}, k, std::vector<double>(static_cast<std::size_t>(nu) * nx * nx * kk));
  for (int l = 0; l < nx; ++l)
    for (int j = 0; j < nx; ++j) {
      const double gv = g[static_cast<std::size_t>(j)], gw = g[static_cast<std::size_t>(l)];
      const double b00 = (1 - gv) * (1 - gw), b10 = gv * (1 - gw), b01 = (1 - gv) * gw, b11 = gv * gw;
      for (int i = 0; i < nu; ++i) {
        auto p = t.point(t.row({i, j, l}));
        const auto a0 = v0.point(v0.row({i, l})), a1 = v1.point(v1.row({i, l}));
        const auto c0 = w0.point(w0.row({i, j})), c1 = w1.point(w1.row({i, j}));
        const std::size_t e = static_cast<std::size_t>(i) * kk;
        for (std::size_t c = 0; c < kk; ++c)
          p[c] = (1 - gv) * a0[c] + gv * a1[c] + (1 - gw) * c0[c] + gw * c1[c] -
                 (b00 * E[0][0][e + c] + b10 * E[1][0][e + c] + b01 * E[0][1][e + c] + b11 * E[1][1][e + c]);
      }
    }
  detail::set_layer(t, 1, 0, v0, "VBS fillet");
  detail::set_layer(t, 1, nx - 1, v1, "VBS fillet");
  detail::set_layer(t, 2, 0, w0, "VBS fillet");
  detail::set_layer(t, 2, nx - 1, w1, "VBS fillet");
  for (int a = 0; a < 2; ++a)
    for (int b2 = 0; b2 < 2; ++b2)
      for (int i = 0; i < nu; ++i) {
        auto p = t.point(t.row({i, a * (nx - 1), b2 * (nx - 1)}));
        const auto& e = E[a][b2];
        std::copy(e.begin() + static_cast<std::ptrdiff_t>(i * k), e.begin() + static_cast<std::ptrdiff_t>((i + 1) * k),
                  p.begin());
      }
  return t;
}

}  // namespace

std::array<Trivariate, 3> vbs_fillet(const Surface& sub1, const Surface& sub2, const Surface& blend,
                                     const VbsOptions& options, VbsReport* report) {
  if (!(options.ratio > 0.0 && options.ratio < 1.0))
    throw Error("VBS fillet: ratio " + num(options.ratio) + "; expected a value in (0, 1) (Eq. A.2: 2 - sqrt 2)");
  if (!(options.tolerance > 0.0))
    throw Error("VBS fillet: tolerance " + num(options.tolerance) + "; expected a value > 0");
  auto [s1, s2, b] = detail::fillet_common_space(sub1, sub2, blend, "VBS fillet");
  const int k = s1.dim(), nv = s1.count(1);
  const auto box = b.control_box();
  const double size = std::hypot(box[1][0] - box[0][0], box[1][1] - box[0][1], box[1][2] - box[0][2]);
  const double tol = options.tolerance * size;

  // Boundaries that must coincide: C twice, the rails twice.
  VbsReport rep;
  rep.rail_gap = {curve_gap(row(b, 0), row(s1, 0)), curve_gap(row(b, nv - 1), row(s2, nv - 1))};
  double jump = 0.0;
  for (int m = 0; m < s1.count(0); ++m) {
    const auto p = s1.point(s1.row({m, nv - 1})), q = s2.point(s2.row({m, 0}));
    for (int j = 3; j < k; ++j) jump = std::max(jump, std::abs(p[static_cast<std::size_t>(j)] - q[static_cast<std::size_t>(j)]));
  }
  rep.property_jump = jump;
  rep.c_gap = detail::join_at_c(s1, s2);
  if (!(rep.c_gap <= tol))
    throw Error("VBS fillet: S^_1(u, 1) and S^_2(u, 0) are " + num(rep.c_gap) +
                " apart; expected the same curve C (within " + num(tol) + ")");
  for (int i = 0; i < 2; ++i)
    if (!(rep.rail_gap[static_cast<std::size_t>(i)] <= tol))
      throw Error("VBS fillet: the blending surface's rail " + std::to_string(i + 1) + " is " +
                  num(rep.rail_gap[static_cast<std::size_t>(i)]) + " from S^_" + std::to_string(i + 1) +
                  "'s; expected the same curve (within " + num(tol) + ")");
  // One curve per rail: S_b takes S^_i's control points there (xyz and g_i).
  set_row(b, 0, row(s1, 0), k);
  set_row(b, nv - 1, row(s2, nv - 1), k);

  // Appendix A / Alg. 7. C carries the mean of g_1 and g_2 (equal to both when they agree on C).
  Curve C = row(s1, nv - 1);
  {
    const Curve c2 = row(s2, 0);
    for (int m = 0; m < C.size(); ++m) {
      auto p = C.point(m);
      const auto q = c2.point(m);
      for (std::size_t j = 3; j < static_cast<std::size_t>(k); ++j) p[j] = 0.5 * (p[j] + q[j]);
    }
  }
  const auto leaves = [](double v, const char* what, const char* surface) {
    if (!(v > 1e-6 && v < 1.0 - 1e-6))
      throw Error(std::string("VBS fillet: the projection ") + what + " on " + surface + " lands at v = " + num(v) +
                      ", its boundary; expected a point inside (a fillet whose cross-section holds a division)",
                  ErrorKind::failed);
  };
  rep.v_b = project(spline::iso(b, 0, 0.5), xyz_at(C, 0.5));  // Eq. A.1
  leaves(rep.v_b, "of C(1/2)", "S_b(1/2, v)");
  auto [ba, bb] = split_across(b, rep.v_b);  // rail 1 -> C_b, C_b -> rail 2
  const Curve Cb = row(ba, ba.count(1) - 1);
  Curve Cc = C;  // Eq. A.2, in xyz and the properties
  for (int m = 0; m < Cc.size(); ++m) {
    auto p = Cc.point(m);
    const auto q = Cb.point(m);
    for (std::size_t j = 0; j < static_cast<std::size_t>(k); ++j) p[j] += options.ratio * (q[j] - p[j]);
  }
  rep.v_1 = project(spline::iso(s1, 0, 0.5), xyz_at(Cc, 0.5));
  leaves(rep.v_1, "of C_c(1/2)", "S^_1(1/2, v)");
  rep.v_2 = project(spline::iso(s2, 0, 0.5), xyz_at(Cc, 0.5));
  leaves(rep.v_2, "of C_c(1/2)", "S^_2(1/2, v)");
  auto [s1a, s1b] = split_across(s1, rep.v_1);  // rail 1 -> C_1, C_1 -> C
  auto [s2a, s2b] = split_across(s2, rep.v_2);  // C -> C_2, C_2 -> rail 2
  const Curve C1 = row(s1a, s1a.count(1) - 1), C2 = row(s2a, s2a.count(1) - 1);
  const Curve R1 = row(s1, 0), R2 = row(s2, nv - 1);

  // The nine sleeve surfaces in one space: U along C (already common), X across.
  enum { S1A, S1B, S2A, S2B, BA, BB, D1, D2, DB, N };
  std::vector<Surface> in{s1a, s1b, s2a, spline::reverse(s2b, 1), ba, bb, construct::ruled(C1, Cc),
                          construct::ruled(Cc, C2), construct::ruled(Cb, Cc)};
  merge_close_knots(in);
  std::vector<Surface> f = construct::common_space<2>(std::span<const Surface>(in));
  for (const auto& s : f)
    if (s.knots(0) != s1.knots(0))
      throw Error("VBS fillet: the sleeve surfaces left C's function space (internal)", ErrorKind::failed);
  // Each shared edge as one set of control points (first / last row across of each surface).
  struct Edge {
    int surface;
    bool last;
    const Curve* curve;
    int coords;
  };
  const Edge edges[] = {{S1A, false, &R1, k}, {S1A, true, &C1, k},  {S1B, false, &C1, k}, {S1B, true, &C, 3},
                        {S2A, false, &C, 3},  {S2A, true, &C2, k},  {S2B, false, &R2, k}, {S2B, true, &C2, k},
                        {BA, false, &R1, k},  {BA, true, &Cb, k},   {BB, false, &Cb, k},  {BB, true, &R2, k},
                        {D1, false, &C1, k},  {D1, true, &Cc, k},   {D2, false, &Cc, k},  {D2, true, &C2, k},
                        {DB, false, &Cb, k},  {DB, true, &Cc, k}};
  for (const auto& e : edges) {
    Surface& s = f[static_cast<std::size_t>(e.surface)];
    set_row(s, e.last ? s.count(1) - 1 : 0, *e.curve, e.coords);
  }

  std::array<Trivariate, 3> cells{cell(f[S1B], f[D2], f[D1], f[S2A]),   // T_1 at C
                                  cell(f[S1A], f[DB], f[BA], f[D1]),    // T_2 at rail 1
                                  cell(f[DB], f[S2B], f[BB], f[D2])};   // T_3 at rail 2
  const double d[3] = {detail::jacobian_at(cells[0], {0.5, 0.5, 0.5}), detail::jacobian_at(cells[1], {0.5, 0.5, 0.5}),
                       detail::jacobian_at(cells[2], {0.5, 0.5, 0.5})};
  if (!((d[0] > 0 && d[1] > 0 && d[2] > 0) || (d[0] < 0 && d[1] < 0 && d[2] < 0)))
    throw Error("VBS fillet: det J at the cells' centres is " + num(d[0]) + ", " + num(d[1]) + " and " + num(d[2]) +
                    "; expected one sign (the division of the cross-section folds)",
                ErrorKind::failed);
  if (d[0] < 0) {
    for (auto& t : cells) t = spline::reverse(t, 0);
    rep.reversed = true;
  }
  rep.centre = rep.reversed ? spline::reverse(Cc, 0) : Cc;
  if (report) *report = std::move(rep);
  return cells;
}

}  // namespace trivox::fillet
