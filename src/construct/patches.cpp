#include "trivox/construct/patches.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "trivox/error.hpp"
#include "trivox/spline/fit.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::construct {

namespace {

using spline::KnotVector;
using spline::Surface;

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string at(int i, int j) { return "patch (" + std::to_string(i) + ", " + std::to_string(j) + ")"; }

/// The knot vector of clamped pieces k (given, each clamped) laid end to end on [0, pieces]: the
/// interior knots of each piece mapped to [k, k+1], joints of multiplicity order - 1.
KnotVector joined_knots(const std::vector<KnotVector>& pieces) {
  const int o = pieces.front().order();
  std::vector<double> knots(static_cast<std::size_t>(o), 0.0);
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    const KnotVector& kv = pieces[k];
    const double a = kv.front(), b = kv.back();
    for (int i = o; i < kv.size(); ++i) knots.push_back(static_cast<double>(k) + (kv[i] - a) / (b - a));
    const int mult = k + 1 == pieces.size() ? o : o - 1;
    for (int m = 0; m < mult; ++m) knots.push_back(static_cast<double>(k + 1));
  }
  return KnotVector(o, std::move(knots));
}

/// Knot vectors equal after mapping both domains onto [0, 1].
bool same_space(const KnotVector& a, const KnotVector& b) {
  if (a.order() != b.order() || a.size() != b.size()) return false;
  const double a0 = a.front(), a1 = a.back(), b0 = b.front(), b1 = b.back();
  for (std::size_t i = 0; i < a.knots().size(); ++i) {
    const double x = (a.knots()[i] - a0) / (a1 - a0), y = (b.knots()[i] - b0) / (b1 - b0);
    if (std::abs(x - y) > 1e-12) return false;
  }
  return true;
}

}  // namespace

Surface merge_patches(std::span<const Surface> patches, int columns, double tolerance, MergeReport* report) {
  if (columns < 1 || patches.empty() || patches.size() % static_cast<std::size_t>(columns) != 0)
    throw Error("merge_patches: " + std::to_string(patches.size()) + " patches in rows of " +
                std::to_string(columns) + "; expected a full grid (a multiple of the row length)");
  const int rows = static_cast<int>(patches.size()) / columns;
  const auto patch = [&](int i, int j) -> const Surface& { return patches[static_cast<std::size_t>(i + columns * j)]; };
  const int dim = patch(0, 0).dim();
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < columns; ++i) {
      const Surface& p = patch(i, j);
      if (p.rational()) throw Error(at(i, j) + " is rational; expected polynomial patches");
      if (p.dim() != dim)
        throw Error(at(i, j) + " has " + std::to_string(p.dim()) + " coordinates; expected " + std::to_string(dim) +
                    " as patch (0, 0)");
      if (!p.knots(0).clamped() || !p.knots(1).clamped()) throw Error(at(i, j) + " is not clamped; expected clamped patches");
      // Along u every patch of column i has the u-space of (i, 0); along v every patch of row j the
      // v-space of (0, j): the merged net is then a tensor grid.
      if (!same_space(p.knots(0), patch(i, 0).knots(0)))
        throw Error(at(i, j) + " has other knots in u than " + at(i, 0) + "; expected one u-space per column");
      if (!same_space(p.knots(1), patch(0, j).knots(1)))
        throw Error(at(i, j) + " has other knots in v than " + at(0, j) + "; expected one v-space per row");
    }
  std::vector<KnotVector> ku, kv;
  for (int i = 0; i < columns; ++i) ku.push_back(patch(i, 0).knots(0));
  for (int j = 0; j < rows; ++j) kv.push_back(patch(0, j).knots(1));
  for (const auto* ks : {&ku, &kv})
    for (const KnotVector& k : *ks)
      if (k.order() != ks->front().order())
        throw Error("merge_patches: patches of orders " + std::to_string(ks->front().order()) + " and " +
                    std::to_string(k.order()) + " in one direction; expected one order per direction (raise it first)");
  const KnotVector KU = joined_knots(ku), KV = joined_knots(kv);
  const int nu = KU.size(), nv = KV.size();
  std::vector<double> pts(static_cast<std::size_t>(nu) * static_cast<std::size_t>(nv) * static_cast<std::size_t>(dim));
  std::vector<char> set(static_cast<std::size_t>(nu) * static_cast<std::size_t>(nv), 0);
  double gap = 0.0;
  int j0 = 0;
  for (int j = 0; j < rows; ++j) {
    int i0 = 0;
    for (int i = 0; i < columns; ++i) {
      const Surface& p = patch(i, j);
      for (int b = 0; b < p.count(1); ++b)
        for (int a = 0; a < p.count(0); ++a) {
          const std::size_t r = static_cast<std::size_t>(i0 + a + nu * (j0 + b));
          const auto q = p.point(p.row({a, b}));
          double* out = pts.data() + r * static_cast<std::size_t>(dim);
          if (set[r]) {
            double d2 = 0.0;
            for (int c = 0; c < dim; ++c) d2 += (out[c] - q[static_cast<std::size_t>(c)]) * (out[c] - q[static_cast<std::size_t>(c)]);
            const double d = std::sqrt(d2);
            gap = std::max(gap, d);
            if (!(d <= tolerance))
              throw Error(at(i, j) + " does not meet its neighbour: control point (" + std::to_string(a) + ", " +
                          std::to_string(b) + ") is " + num(d) + " from the neighbour's; expected patches sharing "
                          "their edges (within " + num(tolerance) + "), u running from patch to patch along a row "
                          "and v from row to row");
            continue;
          }
          std::copy(q.begin(), q.end(), out);
          set[r] = 1;
        }
      i0 += p.count(0) - 1;
    }
    j0 += patch(0, j).count(1) - 1;
  }
  if (report) report->max_gap = gap;
  return Surface({KU, KV}, dim, std::move(pts));
}

namespace {

/// S + d n at (u, v), all coordinates; false where S_u x S_v vanishes.
bool offset_point(const Surface& s, double d, double u, double v, double* der, double* out) {
  s.eval_derivatives({u, v}, 1, der);
  const int k = s.dim();
  const int iu = spline::derivative_slot<2>({1, 0}), iv = spline::derivative_slot<2>({0, 1});
  const double* su = der + iu * k;
  const double* sv = der + iv * k;
  const double n[3] = {su[1] * sv[2] - su[2] * sv[1], su[2] * sv[0] - su[0] * sv[2], su[0] * sv[1] - su[1] * sv[0]};
  const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  const double scale = std::sqrt(su[0] * su[0] + su[1] * su[1] + su[2] * su[2]) *
                       std::sqrt(sv[0] * sv[0] + sv[1] * sv[1] + sv[2] * sv[2]);
  if (!(len > 1e-9 * scale) || !(len > 0.0)) return false;
  for (int c = 0; c < k; ++c) out[c] = der[c] + (c < 3 ? d * n[c] / len : 0.0);
  return true;
}

/// One interpolation of S + d n in a space, and its check.
struct OffsetFit {
  Surface surface;
  double error = 0.0;
  int samples = 0;
  std::vector<double> mid_u, mid_v;  ///< midpoints of the spans holding samples beyond the tolerance
};

class Offsetter {
public:
  Offsetter(const Surface& s, double d, double tol) : s_(s), d_(d), tol_(tol) {
    der_.resize(static_cast<std::size_t>(spline::derivative_count(2, 1) * s.dim()));
    val_.resize(static_cast<std::size_t>(s.dim()));
  }

  /// Interpolation at the Greville points of `space`; the check at 3 x 3 points inside every
  /// knot span (between the interpolation points).
  OffsetFit fit(const Surface& space) {
    const int k = s_.dim();
    const auto gu = space.knots(0).greville(), gv = space.knots(1).greville();
    std::vector<double> values;
    values.reserve(gu.size() * gv.size() * static_cast<std::size_t>(k));
    for (double v : gv)
      for (double u : gu) {
        exact(u, v);
        values.insert(values.end(), val_.begin(), val_.end());
      }
    OffsetFit f{spline::fit_surface_grid(gu, gv, k, values, space.knot_vectors()), 0.0, 0, {}, {}};
    const auto bu = space.knots(0).breakpoints(), bv = space.knots(1).breakpoints();
    std::vector<char> bad_u(bu.size(), 0), bad_v(bv.size(), 0);
    for (std::size_t jb = 0; jb + 1 < bv.size(); ++jb)
      for (std::size_t ib = 0; ib + 1 < bu.size(); ++ib)
        for (double fv : {1.0 / 6, 0.5, 5.0 / 6})
          for (double fu : {1.0 / 6, 0.5, 5.0 / 6}) {
            const double u = bu[ib].value + fu * (bu[ib + 1].value - bu[ib].value);
            const double v = bv[jb].value + fv * (bv[jb + 1].value - bv[jb].value);
            exact(u, v);
            const auto x = f.surface.eval({u, v});
            double d2 = 0.0;
            for (std::size_t c = 0; c < 3; ++c) d2 += (x[c] - val_[c]) * (x[c] - val_[c]);
            const double e = std::sqrt(d2);
            f.error = std::max(f.error, e);
            if (e > tol_) bad_u[ib] = bad_v[jb] = 1;
            ++f.samples;
          }
    for (std::size_t i = 0; i + 1 < bu.size(); ++i)
      if (bad_u[i]) f.mid_u.push_back(0.5 * (bu[i].value + bu[i + 1].value));
    for (std::size_t j = 0; j + 1 < bv.size(); ++j)
      if (bad_v[j]) f.mid_v.push_back(0.5 * (bv[j].value + bv[j + 1].value));
    return f;
  }

private:
  void exact(double u, double v) {
    if (!offset_point(s_, d_, u, v, der_.data(), val_.data()))
      throw Error("offset: the surface is singular at (u, v) = (" + num(u) + ", " + num(v) +
                  ") (S_u x S_v = 0: no normal there); expected a regular surface (restrict it away from a "
                  "collapsed edge)");
  }

  const Surface& s_;
  double d_, tol_;
  std::vector<double> der_, val_;
};

}  // namespace

Surface offset_surface(const Surface& s, double distance, const OffsetOptions& options, OffsetReport* report) {
  if (s.rational()) throw Error("offset: the surface is rational; expected a polynomial surface");
  if (s.dim() < 3) throw Error("offset: the surface has " + std::to_string(s.dim()) + " coordinates; expected 3 or more");
  if (!(std::isfinite(distance) && distance != 0.0))
    throw Error("offset: distance " + num(distance) + "; expected a non-zero finite distance");
  if (!(options.tolerance > 0.0)) throw Error("offset: tolerance " + num(options.tolerance) + "; expected > 0");
  Offsetter off(s, distance, options.tolerance);
  Surface space = s;
  OffsetFit best = off.fit(space);
  int round = 0;
  while (best.error > options.tolerance) {
    if (round >= options.max_refinements)
      throw Error("offset: by " + num(distance) + " still " + num(best.error) + " from S + d n after " +
                      std::to_string(round) + " refinements; expected a tolerance of " + num(options.tolerance) +
                      " (a larger tolerance, or a distance below the surface's radius of curvature)",
                  ErrorKind::failed);
    // Halve the failing spans across u, across v, or both: whichever gets the lowest error (the
    // fewer control points on a near tie). The error is often in one direction only (the foot
    // of the teapot bends sharply in v, hardly in u).
    const Surface su = spline::refine(space, 0, best.mid_u), sv = spline::refine(space, 1, best.mid_v);
    const Surface both = spline::refine(su, 1, best.mid_v);
    OffsetFit fu = off.fit(su), fv = off.fit(sv), fb = off.fit(both);
    const Surface* pick = &both;
    OffsetFit* f = &fb;
    if (fu.error <= 1.1 * fb.error && fu.error <= fv.error) pick = &su, f = &fu;
    else if (fv.error <= 1.1 * fb.error) pick = &sv, f = &fv;
    space = *pick;
    best = std::move(*f);
    ++round;
  }
  if (report) *report = {best.error, round, best.samples};
  return std::move(best.surface);
}

}  // namespace trivox::construct
