/// @file src/fillet/corner_stitch.cpp
/// @brief The concave corner (Masalha et al. 2021, Sec. 6, Fig. 12 (b): "concave discontinuities
/// could be similarly handled ... with C1 discontinuities on the fillet surface, along the
/// trimmed location"): where the two pieces' rails on the smooth face cross, a ruled fillet half
/// clipped by the stitch plane Pi through o, that crossing and r and ruled again (Alg. 2), and
/// a clipped piece's fillet measured again. trivox/fillet/corners.hpp, Step 1b, gives the
/// construction.
///
/// Cost: rails_cross is a Newton iteration on two curves; clip_half per face of the half finds
/// Pi's trace by regula falsi at the Greville points of a cubic space (spans doubled until within
/// a tenth of the tolerance, up to 512), then one sub-region (composed or fitted) and one
/// ruling; remeasure samples det J and integrates the volumes of the piece's cells.
#include <algorithm>
#include <cmath>
#include <limits>

#include "corner_util.hpp"
#include "fillet_util.hpp"
#include "trivox/construct/constructors.hpp"
#include "trivox/error.hpp"
#include "trivox/fillet/compose.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/fit.hpp"

namespace trivox::fillet::detail {

using spline::Curve;
using spline::KnotVector;
using spline::Surface;
using spline::Trivariate;

bool rails_cross(const Curve& ra, const Curve& rb, double& s, double& t) {
  for (int it = 0; it < 60; ++it) {
    const auto a = ra.eval_derivatives({s}, 1), b = rb.eval_derivatives({t}, 1);
    const double fx = a[0] - b[0], fy = a[1] - b[1];
    if (std::hypot(fx, fy) <= 1e-15 * (1.0 + std::hypot(a[0], a[1]))) return true;
    // [a' -b'] (ds, dt) = -f
    const double det = a[2] * (-b[3]) - (-b[2]) * a[3];
    if (!(std::abs(det) > 0.0)) return false;
    const double ds = (-fx * (-b[3]) + b[2] * (-fy)) / det;
    const double dt = (a[2] * (-fy) - a[3] * (-fx)) / det;
    s = std::clamp(s + ds, 0.0, 1.0);
    t = std::clamp(t + dt, 0.0, 1.0);
  }
  return false;
}

namespace {

/// The root in u of (f(u, v) - o) . n on [lo, hi] (sign change from the clipped end `near`
/// towards `far`), or `near` when f(near, v) is already on the kept side (`side` > 0: kept
/// where (f - o) . n has the sign of side). Bisection, then secant polish.
double plane_root(const Surface& f, double v, const Vec& o, const Vec& n, double side, double near, double far) {
  const auto g = [&](double u) { return side * dot(sub(xyz(f.eval({u, v})), o), n); };
  double a = near, b = far, ga = g(a), gb = g(b);
  if (ga >= 0.0) return near;
  if (gb <= 0.0) return far;
  for (int it = 0; it < 200 && std::abs(b - a) > 1e-15 * (1.0 + std::abs(a)); ++it) {
    double m = a - ga * (b - a) / (gb - ga);  // regula falsi (Illinois)
    if (!(m > std::min(a, b) && m < std::max(a, b))) m = 0.5 * (a + b);
    const double gm = g(m);
    if (gm == 0.0) return m;
    if ((gm < 0.0) == (ga < 0.0)) a = m, ga = gm, gb *= 0.5;
    else b = m, gb = gm, ga *= 0.5;
  }
  return 0.5 * (a + b);
}

}  // namespace

Trivariate clip_half(const Trivariate& h, spline::Face end, const Vec& o, const Vec& n, double side, double tol) {
  const auto du = h.domain(0);
  const double near = end == spline::Face::u0 ? du[0] : du[1], far = end == spline::Face::u0 ? du[1] : du[0];
  std::array<Surface, 2> cut;
  for (std::size_t wf = 0; wf < 2; ++wf) {
    const Surface f = spline::boundary_face(h, wf == 0 ? spline::Face::w0 : spline::Face::w1);  // (u, v)
    const auto dv = f.domain(1);
    Curve a;
    bool ok = false;
    for (int spans = 4; spans <= 512 && !ok; spans *= 2) {
      const KnotVector kv = KnotVector::uniform(4, spans, dv[0], dv[1]);
      const std::vector<double> gr = kv.greville();
      std::vector<double> val;
      for (double v : gr) val.push_back(plane_root(f, v, o, n, side, near, far));
      a = spline::interpolate_curve(gr, 1, val, kv);
      double worst = 0.0;
      for (std::size_t j = 0; j + 1 < gr.size(); ++j)
        for (const double t : {0.25, 0.5, 0.75}) {
          const double v = gr[j] + t * (gr[j + 1] - gr[j]);
          const double u = std::clamp(a.eval({v})[0], std::min(near, far), std::max(near, far));
          const double want = plane_root(f, v, o, n, side, near, far);
          worst = std::max(worst, norm(sub(xyz(f.eval({u, v})), xyz(f.eval({want, v})))));
        }
      ok = worst <= 0.1 * tol;
    }
    if (!ok)
      throw Error("fillet stitch at " + at(o) + ": the stitch plane's trace on the fillet does not reach the tolerance " +
                      num(tol) + " with 512 spans",
                  ErrorKind::failed);
    // The map's curves in one cubic space: (a(v), v) and (u_far, v), v by its Greville points.
    const KnotVector& kv = a.knots(0);
    const std::vector<double> gr = kv.greville();
    std::vector<double> pa, pf;
    for (int i = 0; i < kv.size(); ++i) {
      const double ai = std::clamp(a.point(i)[0], std::min(near, far), std::max(near, far));
      pa.insert(pa.end(), {ai, gr[static_cast<std::size_t>(i)]});
      pf.insert(pf.end(), {far, gr[static_cast<std::size_t>(i)]});
    }
    const Curve ca({kv}, 2, std::move(pa)), cf({kv}, 2, std::move(pf));
    SubregionOptions so;
    so.tolerance = 0.25 * tol;
    // s from the clipped end towards the far one along u's own direction.
    const Surface y = end == spline::Face::u0 ? subregion(f, ca, cf, so) : subregion(f, cf, ca, so);  // (v, s)
    cut[wf] = spline::swap_directions(y, 0, 1);
  }
  Trivariate out = construct::ruled(cut[0], cut[1]);
  if (jacobian_at(out, {0.5, 0.5, 0.5}) * jacobian_at(h, {0.5 * (du[0] + du[1]), 0.5, 0.5}) < 0.0)
    throw Error("fillet stitch at " + at(o) + ": the clipped fillet turned inside out", ErrorKind::failed);
  return out;
}

void remeasure(Fillet& fl) {
  FilletQuality& q = fl.quality;
  q.cell_jacobian.clear();
  q.cell_volume.clear();
  q.det_min = std::numeric_limits<double>::infinity();
  q.det_max = -q.det_min;
  for (const Trivariate& h : fl.cells) {
    const std::array<double, 2> r = sampled_jacobian(h);
    q.cell_jacobian.push_back(r);
    q.cell_volume.push_back(std::abs(boundary_volume(h)));
    q.det_min = std::min(q.det_min, r[0]);
    q.det_max = std::max(q.det_max, r[1]);
  }
  q.glue = face_gaps(spline::boundary_face(fl.cells.at(0), spline::Face::v1), spline::boundary_face(fl.cells.at(1), spline::Face::v0))[0];
  q.cells.clear();
  for (const Trivariate& h : fl.cells) {
    SplineShape sh;
    for (int d = 0; d < 3; ++d) sh.orders.push_back(h.orders()[static_cast<std::size_t>(d)]), sh.counts.push_back(h.count(d));
    q.cells.push_back(sh);
  }
  q.fillet = q.cells.front();
}

}  // namespace trivox::fillet::detail
