#include "trivox/fillet/fillet.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "fillet_util.hpp"
#include "trivox/error.hpp"
#include "trivox/fillet/rails.hpp"
#include "trivox/fillet/ruled_fillet.hpp"
#include "trivox/geom/closest_point.hpp"
#include "trivox/geom/surface_intersection.hpp"
#include "trivox/spline/extract.hpp"

namespace trivox::fillet {

using spline::Curve;
using spline::Face;
using spline::Surface;
using spline::Trivariate;
using detail::Vec;
using namespace detail;

std::string FilletQuality::jacobian() const {
  if (det_min > 0.0) return "positive";
  if (det_max < 0.0) return "negative";
  return "changes sign";
}

namespace {

template <int P>
SplineShape shape(const spline::TensorSpline<P>& s) {
  SplineShape out;
  for (int d = 0; d < P; ++d) {
    out.orders.push_back(s.orders()[static_cast<std::size_t>(d)]);
    out.counts.push_back(s.counts()[static_cast<std::size_t>(d)]);
  }
  return out;
}

/// Unit normal of s at (u, v); zero where s is singular.
Vec unit_normal(const Surface& s, double u, double v, Vec* across = nullptr) {
  const auto d = s.eval_derivatives({u, v}, 1);
  const std::size_t k = static_cast<std::size_t>(s.dim());
  Vec n = cross(xyz(d.data() + k), xyz(d.data() + 2 * k));
  if (across) *across = {d[2 * k], d[2 * k + 1], d[2 * k + 2]};
  const double len = norm(n);
  if (len > 0.0)
    for (double& x : n) x /= len;
  return n;
}

double diagonal(const Trivariate& a, const Trivariate& b) {
  const auto ba = spline::bounding_box(a, 3), bb = spline::bounding_box(b, 3);
  double s = 0.0;
  for (std::size_t j = 0; j < 3; ++j) {
    const double lo = std::min(ba[0][j], bb[0][j]), hi = std::max(ba[1][j], bb[1][j]);
    s += (hi - lo) * (hi - lo);
  }
  return std::sqrt(s);
}

/// The quality report of seed 000's fillet (see fillet.hpp).
void measure(const std::array<const Surface*, 2>& faces, const std::array<Curve, 2>& rail_uv, const Surface& blend,
             const Fillet& f, FilletQuality& q) {
  const int k = faces[0]->dim();
  for (int i = 0; i < 2; ++i) {
    const std::size_t si = static_cast<std::size_t>(i);
    // Gap and property jump: the fillet's face on S_i (w = 0) against S_i at the closest point.
    const geom::SurfaceDistance dist(*faces[si]);
    const Surface on = spline::boundary_face(f.halves[si], Face::w0);
    std::vector<double> p(static_cast<std::size_t>(k)), g(static_cast<std::size_t>(k));
    constexpr int nu = 32, nv = 8;
    for (int a = 0; a <= nu; ++a)
      for (int b = 0; b <= nv; ++b) {
        on.eval({static_cast<double>(a) / nu, static_cast<double>(b) / nv}, p.data());
        const auto cp = dist.closest({p[0], p[1], p[2]});
        q.gap[si] = std::max(q.gap[si], cp.distance);
        faces[si]->eval(cp.uv, g.data());
        for (int j = 3; j < k; ++j)
          q.property_jump[si] = std::max(q.property_jump[si], std::abs(p[static_cast<std::size_t>(j)] - g[static_cast<std::size_t>(j)]));
      }
    // G1 along rail i: S_b's normal at v = i against the face's normal at the rail's parameters.
    constexpr int nt = 200;
    double worst = 0.0;
    for (int a = 0; a <= nt; ++a) {
      const double t = static_cast<double>(a) / nt;
      Vec along;
      const Vec nb = unit_normal(blend, t, static_cast<double>(i), &along);
      if (norm(nb) == 0.0) continue;  // a rail standing still or a vanishing cross tangent (dip 0)
      double uv[2];
      rail_uv[si].eval({t}, uv);
      const auto du = faces[si]->domain(0), dv = faces[si]->domain(1);
      const Vec nf = unit_normal(*faces[si], std::clamp(uv[0], du[0], du[1]), std::clamp(uv[1], dv[0], dv[1]));
      worst = std::max(worst, std::acos(std::min(1.0, std::abs(dot(nb, nf)))));
    }
    q.g1_angle[si] = worst;
  }
  // det J at interior points of both halves.
  q.det_min = std::numeric_limits<double>::infinity();
  q.det_max = -q.det_min;
  constexpr int n0 = 16, n1 = 6, n2 = 4;
  for (const Trivariate& h : f.halves)
    for (int a = 0; a < n0; ++a)
      for (int b = 0; b < n1; ++b)
        for (int c = 0; c < n2; ++c) {
          const double det = jacobian_at(h, {(a + 0.5) / n0, (b + 0.5) / n1, (c + 0.5) / n2});
          q.det_min = std::min(q.det_min, det);
          q.det_max = std::max(q.det_max, det);
        }
}

}  // namespace

double outward_sign(const Trivariate& cell, Face face) {
  const int dir = static_cast<int>(face) / 2;
  const bool at_max = static_cast<int>(face) % 2 == 1;
  std::array<double, 3> t{};
  for (int d = 0; d < 3; ++d) {
    const auto dom = cell.domain(d);
    t[static_cast<std::size_t>(d)] = d == dir ? dom[at_max ? 1 : 0] : 0.5 * (dom[0] + dom[1]);
  }
  const auto der = cell.eval_derivatives(t, 1);
  const std::size_t k = static_cast<std::size_t>(cell.dim());
  int others[2], n = 0;
  for (int d = 0; d < 3; ++d)
    if (d != dir) others[n++] = d;
  const Vec normal = cross(xyz(der.data() + k * (1 + others[0])), xyz(der.data() + k * (1 + others[1])));
  const double* inward = der.data() + k * (1 + dir);
  const double s = dot(normal, {inward[0], inward[1], inward[2]}) * (at_max ? 1.0 : -1.0);
  if (s == 0.0)
    throw Error("face " + std::string(spline::face_name(face)) + " is singular at its centre; cannot tell its outside",
                ErrorKind::failed);
  return s > 0.0 ? 1.0 : -1.0;
}

std::vector<Fillet> fillet_faces(const Trivariate& cell1, Face f1, const Trivariate& cell2, Face f2,
                                 const FilletOptions& o) {
  if (cell1.dim() != cell2.dim())
    throw Error("fillet: the cells have " + std::to_string(cell1.dim()) + " and " + std::to_string(cell2.dim()) +
                " coordinates; expected the same (xyz and the same properties)");
  if (cell1.dim() < 3) throw Error("fillet: cells need at least 3 coordinates");
  for (int i = 0; i < 2; ++i)
    if (!(o.distance[static_cast<std::size_t>(i)] > 0.0) || !std::isfinite(o.distance[static_cast<std::size_t>(i)]))
      throw Error("fillet: distance " + num(o.distance[static_cast<std::size_t>(i)]) + "; expected a positive value");
  const double tol = o.tolerance > 0.0 ? o.tolerance : 1e-7 * diagonal(cell1, cell2);
  const Surface s1 = spline::boundary_face(cell1, f1), s2 = spline::boundary_face(cell2, f2);
  const std::array<double, 2> outward{outward_sign(cell1, f1), outward_sign(cell2, f2)};
  geom::IntersectionOptions io;
  io.tolerance = tol;
  const std::vector<geom::IntersectionCurve> curves = geom::intersect_surfaces(s1, s2, io);
  if (curves.empty()) {
    // Tangent contact is no curve for the intersection either; tell it from no contact at all.
    const geom::SurfaceDistance to2(s2);
    geom::ClosestPoint best;
    best.distance = std::numeric_limits<double>::infinity();
    constexpr int n = 32;
    std::vector<double> p(static_cast<std::size_t>(s1.dim()));
    for (int a = 0; a <= n; ++a)
      for (int b = 0; b <= n; ++b) {
        const auto du = s1.domain(0), dv = s1.domain(1);
        s1.eval({du[0] + (du[1] - du[0]) * a / n, dv[0] + (dv[1] - dv[0]) * b / n}, p.data());
        const auto cp = to2.closest({p[0], p[1], p[2]});
        if (cp.distance < best.distance) best = cp;
      }
    if (best.distance <= 1e3 * tol)
      throw Error("fillet: the faces touch without crossing, near (" + num(best.point[0]) + ", " + num(best.point[1]) +
                  ", " + num(best.point[2]) + "); expected faces that cross along a curve");
    throw Error("fillet: the faces do not intersect (they come no closer than " + num(best.distance) +
                "); expected faces that cross along a curve");
  }
  std::vector<Fillet> out;
  for (const auto& curve : curves) {
    if (curve.points.size() < 2 || curve.xyz.size() == 0)
      throw Error("fillet: the faces touch at a point (" + num(curve.points[0].xyz[0]) + ", " +
                  num(curve.points[0].xyz[1]) + ", " + num(curve.points[0].xyz[2]) +
                  "); expected faces that cross along a curve");
    // A contact that only just crosses (a tangent contact, or within the cells' own accuracy)
    // is a point for the fillet: far smaller than the distances it is to be offset by.
    std::array<double, 3> lo{}, hi{};
    lo.fill(std::numeric_limits<double>::infinity());
    hi.fill(-std::numeric_limits<double>::infinity());
    for (const auto& pt : curve.points)
      for (std::size_t j = 0; j < 3; ++j) lo[j] = std::min(lo[j], pt.xyz[j]), hi[j] = std::max(hi[j], pt.xyz[j]);
    const double extent = std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    if (extent < 0.1 * std::min(o.distance[0], o.distance[1]))
      throw Error("fillet: the faces touch at a point: their intersection near (" + num(lo[0]) + ", " + num(lo[1]) +
                  ", " + num(lo[2]) + ") spans " + num(extent) + ", far less than the distance " +
                  num(std::min(o.distance[0], o.distance[1])) + "; expected faces that cross along a curve");
    const auto start = std::chrono::steady_clock::now();
    RailOptions ro;
    ro.tolerance = tol;
    ro.flip = o.flip;
    const RailPair rp = offset_rails(s1, s2, outward, curve, o.distance, ro);
    SubregionOptions so;
    so.method = o.method;
    so.tolerance = tol;
    Fillet f;
    SubregionReport r1, r2;
    const Surface sub1 = subregion(s1, rp.rails[0].rail, rp.rails[0].base, so, &r1);
    const Surface sub2 = subregion(s2, rp.rails[1].base, rp.rails[1].rail, so, &r2);
    BlendInput in;
    in.faces = {&s1, &s2};
    in.rail_uv = {rp.rails[0].rail, rp.rails[1].rail};
    in.rail = {spline::iso(sub1, 1, 0.0), spline::iso(sub2, 1, 1.0)};
    in.center = spline::iso(sub1, 1, 1.0);
    const Surface blend = blending_surface(in, o.blend);
    f.halves = ruled_fillet(sub1, sub2, blend);
    FilletQuality& q = f.quality;
    q.composed = {r1.composed, r2.composed};
    q.rail_error = {rp.rails[0].max_error, rp.rails[1].max_error};
    q.face[0] = shape(s1);
    q.face[1] = shape(s2);
    q.sub[0] = shape(sub1);
    q.sub[1] = shape(sub2);
    q.blend = shape(blend);
    q.fillet = shape(f.halves[0]);
    q.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    measure({&s1, &s2}, in.rail_uv, blend, f, q);
    out.push_back(std::move(f));
  }
  return out;
}

}  // namespace trivox::fillet
