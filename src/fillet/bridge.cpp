#include "trivox/fillet/bridge.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "trivox/construct/constructors.hpp"
#include "fillet_util.hpp"
#include "trivox/error.hpp"
#include "trivox/geom/surface_intersection.hpp"
#include "trivox/spline/calculus.hpp"
#include "trivox/spline/fit.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::fillet {

using spline::KnotVector;
using spline::Surface;
using spline::Trivariate;
using detail::Vec;
using namespace detail;

namespace {

/// The face's (u, v) transformed: swapped, then reversed in u and/or v.
Surface oriented(Surface s, int code) {
  if (code & 4) s = spline::swap_directions(s, 0, 1);
  if (code & 1) s = spline::reverse(s, 0);
  if (code & 2) s = spline::reverse(s, 1);
  return construct::normalized(s);
}

std::string orientation_name(int code) {
  if (code == 0) return "as is";
  std::string s;
  if (code & 4) s += "u and v swapped";
  if (code & 1) s += std::string(s.empty() ? "" : ", ") + "u reversed";
  if (code & 2) s += std::string(s.empty() ? "" : ", ") + "v reversed";
  return s;
}

/// The derivative of a cell across its face f, on the face, pointing out of the cell (xyz).
Surface outward_field(const Trivariate& cell, spline::Face f) {
  const int dir = static_cast<int>(f) / 2;
  const bool at_max = static_cast<int>(f) % 2 == 1;
  const Trivariate d = spline::derivative(spline::coordinates(cell, 0, 3), dir);
  Surface s = spline::iso(d, dir, cell.domain(dir)[at_max ? 1 : 0]);
  if (!at_max)
    for (double& x : s.points()) x = -x;
  return s;
}

struct Rows {
  Vec p1, p2, p3, d_a, d_b;
};

/// Flends Sec. III.A at one point: the faux intersection and the section's inner points.
Rows section(const Vec& pa, Vec da, const Vec& pb, Vec db, double dip, double u, double v) {
  const double la = norm(da), lb = norm(db);
  if (!(la > 0.0) || !(lb > 0.0))
    throw Error("bridge: a cell is singular across its face at (u, v) = (" + num(u) + ", " + num(v) + ")",
                ErrorKind::failed);
  for (double& x : da) x /= la;
  for (double& x : db) x /= lb;
  const Vec w0 = sub(pa, pb);
  const double b = dot(da, db), d = dot(da, w0), e = dot(db, w0);
  const double denom = 1.0 - b * b;
  Vec pi;
  double t, s;
  if (denom > 1e-9) {
    t = (b * e - d) / denom;
    s = (e - b * d) / denom;
    const Vec ca = axpy(pa, t, da), cb = axpy(pb, s, db);
    pi = {0.5 * (ca[0] + cb[0]), 0.5 * (ca[1] + cb[1]), 0.5 * (ca[2] + cb[2])};
  } else {  // parallel end lines: no closest points; the midpoint
    pi = {0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1]), 0.5 * (pa[2] + pb[2])};
    t = dot(sub(pi, pa), da);
    s = dot(sub(pi, pb), db);
  }
  if (!(t > 0.0) || !(s > 0.0))
    throw Error("bridge: the faces do not face each other at (u, v) = (" + num(u) + ", " + num(v) +
                "): the end lines meet behind a face; expected faces that look at each other");
  Rows r;
  r.d_a = da;
  r.d_b = db;
  r.p1 = axpy(pa, dip * t, da);
  r.p3 = axpy(pb, dip * s, db);
  const Vec ps = axpy(r.p1, dip, sub(pi, r.p1)), pss = axpy(r.p3, dip, sub(pi, r.p3));
  r.p2 = {0.5 * (ps[0] + pss[0]), 0.5 * (ps[1] + pss[1]), 0.5 * (ps[2] + pss[2])};
  return r;
}

double angle(const Vec& x, const Vec& unit) {
  const double l = norm(x);
  return l > 0.0 ? std::acos(std::clamp(dot(x, unit) / l, -1.0, 1.0)) : 0.0;
}

}  // namespace

Trivariate bridge(const Trivariate& cell1, spline::Face fa, const Trivariate& cell2, spline::Face fb,
                  const BridgeOptions& o, BridgeQuality* quality) {
  if (cell1.dim() != cell2.dim())
    throw Error("bridge: the cells have " + std::to_string(cell1.dim()) + " and " + std::to_string(cell2.dim()) +
                " coordinates; expected the same");
  if (cell1.dim() < 3 || cell1.rational() || cell2.rational())
    throw Error("bridge: expected polynomial cells with xyz");
  if (!(o.dip >= 0.0 && o.dip <= 1.0)) throw Error("bridge: dip " + num(o.dip) + "; expected a value in [0, 1]");
  const Surface a0 = construct::normalized(spline::boundary_face(cell1, fa));
  const Surface b0 = spline::boundary_face(cell2, fb);
  if (!geom::intersect_surfaces(a0, b0).empty())
    throw Error("bridge: the faces meet; expected disjoint faces (a fillet joins faces that cross)");
  // B's orientation: the one of the eight that puts its corners nearest A's.
  int best = 0;
  double best_d = std::numeric_limits<double>::infinity();
  for (int code = 0; code < 8; ++code) {
    const Surface b = oriented(b0, code);
    double d = 0.0;
    for (double u : {0.0, 1.0})
      for (double v : {0.0, 1.0}) d += norm(sub(xyz(a0.eval({u, v})), xyz(b.eval({u, v}))));
    if (d < best_d - 1e-12 * (1.0 + best_d)) best_d = d, best = code;
  }
  const Surface da = construct::normalized(outward_field(cell1, fa));
  const Surface db = oriented(outward_field(cell2, fb), best);
  const Surface parts[2] = {a0, oriented(b0, best)};
  std::vector<Surface> ab = construct::common_space<2>(parts);
  const int k = cell1.dim();
  const KnotVector across(4, {0, 0, 0, 0, 0.5, 1, 1, 1, 1});
  const double greville[5] = {0.0, 1.0 / 6, 0.5, 5.0 / 6, 1.0};
  BridgeQuality q;
  q.orientation = orientation_name(best);
  for (int round = 0; round <= o.max_rounds; ++round) {
    const std::array<KnotVector, 2> kv{ab[0].knots(0), ab[0].knots(1)};
    const std::vector<double> gu = kv[0].greville(), gv = kv[1].greville();
    const auto exact = [&](double u, double v) {
      return section(xyz(ab[0].eval({u, v})), xyz(da.eval({u, v})), xyz(ab[1].eval({u, v})), xyz(db.eval({u, v})),
                     o.dip, u, v);
    };
    std::array<std::vector<double>, 3> data;
    for (auto& d : data) d.reserve(3 * gu.size() * gv.size());
    for (double v : gv)
      for (double u : gu) {
        const Rows r = exact(u, v);
        data[0].insert(data[0].end(), r.p1.begin(), r.p1.end());
        data[1].insert(data[1].end(), r.p2.begin(), r.p2.end());
        data[2].insert(data[2].end(), r.p3.begin(), r.p3.end());
      }
    std::array<Surface, 3> inner;
    for (int r = 0; r < 3; ++r) inner[static_cast<std::size_t>(r)] = spline::fit_surface_grid(gu, gv, 3, data[static_cast<std::size_t>(r)], kv);
    // G1 between the samples: P_1 - P_0 along d_A, P_3 - P_4 along d_B.
    std::array<double, 2> worst{0.0, 0.0};
    for (std::size_t j = 0; j + 1 < gv.size(); ++j)
      for (std::size_t i = 0; i + 1 < gu.size(); ++i) {
        const double u = 0.5 * (gu[i] + gu[i + 1]), v = 0.5 * (gv[j] + gv[j + 1]);
        const Rows r = exact(u, v);
        const Vec p0 = xyz(ab[0].eval({u, v})), p4 = xyz(ab[1].eval({u, v}));
        worst[0] = std::max(worst[0], angle(sub(xyz(inner[0].eval({u, v})), p0), r.d_a));
        worst[1] = std::max(worst[1], angle(sub(xyz(inner[2].eval({u, v})), p4), r.d_b));
      }
    if (std::max(worst[0], worst[1]) > o.angle_tolerance) {
      if (round == o.max_rounds)
        throw Error("bridge: the section rows stay " + num(std::max(worst[0], worst[1])) +
                        " rad off the end directions after " + std::to_string(o.max_rounds) + " refinements",
                    ErrorKind::failed);
      for (auto& s : ab) {
        s = spline::to_space(s, 0, halved(kv[0]));
        s = spline::to_space(s, 1, halved(kv[1]));
      }
      continue;
    }
    q.g1_angle = worst;
    // Rows in R^k: xyz as built, properties linear in w (Greville abscissae of the section).
    std::vector<Surface> rows;
    for (int r = 0; r < 5; ++r) {
      Surface row = ab[0];
      for (int c = 0; c < row.size(); ++c) {
        auto out = row.point(c);
        const auto pa = ab[0].point(c), pb = ab[1].point(c);
        if (r == 4)
          for (int j = 0; j < 3; ++j) out[static_cast<std::size_t>(j)] = pb[static_cast<std::size_t>(j)];
        else if (r > 0)
          for (int j = 0; j < 3; ++j)
            out[static_cast<std::size_t>(j)] = inner[static_cast<std::size_t>(r - 1)].point(c)[static_cast<std::size_t>(j)];
        for (int j = 3; j < k; ++j)
          out[static_cast<std::size_t>(j)] = (1.0 - greville[r]) * pa[static_cast<std::size_t>(j)] + greville[r] * pb[static_cast<std::size_t>(j)];
      }
      rows.push_back(std::move(row));
    }
    Trivariate t = construct::stack<3>(rows, 2, across);
    // det J inside; right-handed.
    q.det_min = std::numeric_limits<double>::infinity();
    q.det_max = -q.det_min;
    constexpr int n = 8;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int l = 0; l < n; ++l) {
          const double det = jacobian_at(t, {(i + 0.5) / n, (j + 0.5) / n, (l + 0.5) / n});
          q.det_min = std::min(q.det_min, det);
          q.det_max = std::max(q.det_max, det);
        }
    if (q.det_min < 0.0 && q.det_max > 0.0)
      throw Error("bridge: det J changes sign inside (from " + num(q.det_min) + " to " + num(q.det_max) +
                      "); expected a valid bridge: try another dip",
                  ErrorKind::failed);
    if (q.det_max < 0.0) {
      t = spline::reverse(t, 0);
      const double lo = q.det_min;
      q.det_min = -q.det_max;
      q.det_max = -lo;
    }
    if (quality) *quality = q;
    return t;
  }
  throw Error("bridge: internal: no result", ErrorKind::failed);
}

}  // namespace trivox::fillet
