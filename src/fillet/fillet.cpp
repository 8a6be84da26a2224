#include "trivox/fillet/fillet.hpp"

#include "trivox/fillet/matched.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>

#include "fillet_util.hpp"
#include "trivox/error.hpp"
#include "trivox/fillet/rails.hpp"
#include "trivox/fillet/ruled_fillet.hpp"
#include "trivox/fillet/vbs_fillet.hpp"
#include "trivox/fillet/vrep_fillet.hpp"
#include "trivox/geom/closest_point.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/geom/surface_intersection.hpp"
#include "trivox/spline/calculus.hpp"
#include "trivox/spline/extract.hpp"

namespace trivox::fillet {

using spline::Curve;
using spline::Face;
using spline::Surface;
using spline::Trivariate;
using detail::Vec;
using namespace detail;

const char* construction_name(Construction c) noexcept {
  return c == Construction::vbs ? "vbs" : c == Construction::vrep ? "vrep" : "ruled";
}

bool construction_from_name(const char* name, Construction& out) noexcept {
  for (Construction c : {Construction::ruled, Construction::vbs, Construction::vrep})
    if (std::strcmp(name, construction_name(c)) == 0) {
      out = c;
      return true;
    }
  return false;
}

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

double diagonal(const Trivariate& a, const Trivariate& b) {
  const auto ba = spline::bounding_box(a, 3), bb = spline::bounding_box(b, 3);
  double s = 0.0;
  for (std::size_t j = 0; j < 3; ++j) {
    const double lo = std::min(ba[0][j], bb[0][j]), hi = std::max(ba[1][j], bb[1][j]);
    s += (hi - lo) * (hi - lo);
  }
  return std::sqrt(s);
}

/// A face of one of the fillet's parts: its cells, then (vrep) the trimming solid's W_1, W_2.
struct FaceRef {
  std::size_t cell;
  Face face;
};

/// Where a construction's cells meet the input surfaces and each other (ruled_fillet.hpp and
/// vbs_fillet.hpp list the faces). rail[i]: the cell face on S_b whose edge across-parameter
/// v = rail[i].v (boundary_face's second parameter) lies on rail i.
struct Layout {
  std::vector<FaceRef> on[2];
  std::vector<std::pair<FaceRef, std::array<double, 2>>> on_blend;  ///< with the range of S_b's v it covers
  std::vector<std::pair<FaceRef, FaceRef>> shared;
  struct RailEdge {
    FaceRef face;
    double v;
  } rail[2];
};

Layout layout(Construction c, double v_b) {
  Layout l;
  if (c == Construction::vrep) {
    // Alg. 6: T_hbs (part 0) w0 = S^_1, v0 = S^_2 (Lemma 2); S_b is the face w0 of W_1 (part 1,
    // S_b[0, v_b], rail 1 at its v = 0) and of W_2 (part 2, S_b[v_b, 1], rail 2 at v = 1), which
    // share Rld(C_b, K).
    l.on[0] = {{0, Face::w0}};
    l.on[1] = {{0, Face::v0}};
    l.on_blend = {{{1, Face::w0}, {0.0, v_b}}, {{2, Face::w0}, {v_b, 1.0}}};
    l.shared = {{{1, Face::v1}, {2, Face::v0}}};
    l.rail[0] = {{1, Face::w0}, 0.0};
    l.rail[1] = {{2, Face::w0}, 1.0};
  } else if (c == Construction::ruled) {
    // Alg. 2: half a = ruled(S^_1, S_b[0, 1/2]), half b = ruled(S^_2, S_b[1/2, 1]); w = 0 on S^_i.
    l.on[0] = {{0, Face::w0}};
    l.on[1] = {{1, Face::w0}};
    l.on_blend = {{{0, Face::w1}, {0.0, 0.5}}, {{1, Face::w1}, {0.5, 1.0}}};
    l.shared = {{{0, Face::v1}, {1, Face::v0}}};
    l.rail[0] = {{0, Face::w1}, 0.0};
    l.rail[1] = {{1, Face::w1}, 1.0};
  } else {
    // Alg. 3: T_1 v0 = S^_1[v_1, 1], w1 = S^_2[0, v_2]; T_2 v0 = S^_1[0, v_1], w0 = S_b[0, v_b];
    // T_3 v1 = S^_2[v_2, 1], w0 = S_b[v_b, 1]; D_1, D_2, D_b shared.
    l.on[0] = {{0, Face::v0}, {1, Face::v0}};
    l.on[1] = {{0, Face::w1}, {2, Face::v1}};
    l.on_blend = {{{1, Face::w0}, {0.0, v_b}}, {{2, Face::w0}, {v_b, 1.0}}};
    l.shared = {{{0, Face::w0}, {1, Face::w1}}, {{0, Face::v1}, {2, Face::w1}}, {{1, Face::v1}, {2, Face::v0}}};
    l.rail[0] = {{1, Face::w0}, 0.0};
    l.rail[1] = {{2, Face::w0}, 1.0};
  }
  return l;
}

const Trivariate& part(const Fillet& f, std::size_t i) {
  return i < f.cells.size() ? f.cells[i] : f.beyond.at(i - f.cells.size());
}

Surface face_of(const Fillet& f, const FaceRef& r) { return spline::boundary_face(part(f, r.cell), r.face); }

/// The quality report of Masalha et al. 2021's fillet (see fillet.hpp), for either construction.
void measure(const std::array<const Surface*, 2>& faces, const Surface& blend, const Fillet& f, FilletQuality& q) {
  const Layout l = layout(q.construction, q.construction == Construction::vrep ? q.vrep.v_b : q.vbs.v_b);
  const int k = faces[0]->dim();
  std::vector<double> p(static_cast<std::size_t>(k)), g(static_cast<std::size_t>(k));
  constexpr int nu = 32, nv = 8;
  const auto grid = [&](const Surface& s, auto&& at) {
    const auto du = s.domain(0), dv = s.domain(1);
    for (int a = 0; a <= nu; ++a)
      for (int b = 0; b <= nv; ++b) at(du[0] + (du[1] - du[0]) * a / nu, dv[0] + (dv[1] - dv[0]) * b / nv);
  };
  for (int i = 0; i < 2; ++i) {
    const std::size_t si = static_cast<std::size_t>(i);
    // Gap and property jump: the cells' faces on S_i against S_i at the closest point.
    const geom::SurfaceDistance dist(*faces[si]);
    for (const FaceRef& r : l.on[si]) {
      const Surface on = face_of(f, r);
      grid(on, [&](double u, double v) {
        on.eval({u, v}, p.data());
        const auto cp = dist.closest({p[0], p[1], p[2]});
        q.gap[si] = std::max(q.gap[si], cp.distance);
        faces[si]->eval(cp.uv, g.data());
        for (int j = 3; j < k; ++j)
          q.property_jump[si] =
              std::max(q.property_jump[si], std::abs(p[static_cast<std::size_t>(j)] - g[static_cast<std::size_t>(j)]));
      });
    }
    // G1 along rail i: the normal of the cell face on S_b at the rail against S_i's at the
    // closest point.
    const Surface on_b = face_of(f, l.rail[si].face);
    const double vr = on_b.domain(1)[l.rail[si].v > 0.5 ? 1 : 0];
    constexpr int nt = 200;
    double worst = 0.0;
    for (int a = 0; a <= nt; ++a) {
      const auto du = on_b.domain(0);
      const double t = du[0] + (du[1] - du[0]) * a / nt;
      // A rail standing still or a vanishing cross tangent (dip 0): no tangent plane to compare.
      const auto d = on_b.eval_derivatives({t, vr}, 1);
      const std::size_t kb = static_cast<std::size_t>(on_b.dim());
      const double su = norm(xyz(d.data() + kb)), sv = norm(xyz(d.data() + 2 * kb));
      if (!(su > 0.0) || !(sv > 1e-9 * su)) continue;
      const Vec nb = unit_normal(on_b, t, vr);
      on_b.eval({t, vr}, p.data());
      const auto cp = dist.closest({p[0], p[1], p[2]});
      const Vec nf = unit_normal(*faces[si], cp.uv[0], cp.uv[1]);
      worst = std::max(worst, std::acos(std::min(1.0, std::abs(dot(nb, nf)))));
    }
    q.g1_angle[si] = worst;
  }
  // The faces on S_b: Newton on S_b from the parameter each face point comes from (u or 1 - u,
  // the cells may be reversed), the nearer of the two. An upper bound of the distance; a cold
  // query is unreliable here, where S_b is singular on the rails (dip 0: S_b,v = 0).
  const geom::SurfaceDistance to_blend(spline::coordinates(blend, 0, 3), 2);
  const auto bu = blend.domain(0), bv = blend.domain(1);
  for (const auto& [r, range] : l.on_blend) {
    const Surface on = face_of(f, r);
    const auto du = on.domain(0), dv = on.domain(1);
    // Captured by name: clang before version 16 cannot capture a structured binding.
    grid(on, [&, &range = range](double u, double v) {
      on.eval({u, v}, p.data());
      const double a = (u - du[0]) / (du[1] - du[0]), b = (v - dv[0]) / (dv[1] - dv[0]);
      const double sv = bv[0] + (bv[1] - bv[0]) * (range[0] + b * (range[1] - range[0]));
      double best = std::numeric_limits<double>::infinity();
      for (const double su : {bu[0] + (bu[1] - bu[0]) * a, bu[1] - (bu[1] - bu[0]) * a})
        best = std::min(best, to_blend.closest({p[0], p[1], p[2]}, {su, sv}).distance);
      q.blend_gap = std::max(q.blend_gap, best);
    });
  }
  // C0 glue: the shared faces at the same parameters.
  for (const auto& [ra, rb] : l.shared) {
    const Surface a = face_of(f, ra), b = face_of(f, rb);
    std::vector<double> x(static_cast<std::size_t>(k));
    grid(a, [&](double u, double v) {
      a.eval({u, v}, p.data());
      b.eval({u, v}, x.data());
      q.glue = std::max(q.glue, std::hypot(p[0] - x[0], p[1] - x[1], p[2] - x[2]));
    });
  }
  // det J at interior points of every cell: per knot span along C, 6 x 4 (ruled: few w) or
  // 6 x 6 (vbs, vrep: T_hbs untrimmed) across. Sampled, not bounded: check_validity chases the zero rail edges of
  // thousand-span cells for minutes (Masalha et al. 2021, Sec. 9: det J vanishes on the rails).
  q.det_min = std::numeric_limits<double>::infinity();
  q.det_max = -q.det_min;
  const int n1 = 6, n2 = q.construction == Construction::ruled ? 4 : 6;
  for (const Trivariate& h : f.cells) {
    const std::array<double, 2> range = sampled_jacobian(h, n1, n2);
    q.cell_jacobian.push_back(range);
    // vrep: the trimmed cell, T_hbs less the solid beyond S_b (inside it: VrepReport::outside).
    q.cell_volume.push_back(q.construction == Construction::vrep
                                ? q.vrep.hbs_volume - q.vrep.beyond_volume[0] - q.vrep.beyond_volume[1]
                                : std::abs(boundary_volume(h)));
    q.det_min = std::min(q.det_min, range[0]);
    q.det_max = std::max(q.det_max, range[1]);
  }
}

}  // namespace

vmodel::VCell Fillet::vcell(std::size_t c, const std::string& name) const {
  if (beyond.empty()) return vmodel::VCell(name, cells.at(c));
  VrepFillet v;
  v.hbs = cells.at(c);
  v.beyond = {beyond.at(0), beyond.at(1)};
  v.caps = caps;
  return v.cell(name);
}

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
  for (std::size_t ci = 0; ci < curves.size(); ++ci) {
    const geom::IntersectionCurve& curve = curves[ci];
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
    so.method = o.method;  // subregion() composes for `matched` (only the whole curve lands there)
    so.tolerance = tol;
    // The sub-regions and blending inputs: one pair over the whole curve, or, for B-spline faces
    // whose knot lines C crosses, one matched Bezier pair per piece (Masalha et al. 2021, Alg.
    // 4-5), each composed exactly; "auto" falls back to fitting (Sec. 4.3) when
    // Lemma 1's condition fails.
    struct Part {
      Surface sub1, sub2;
      BlendInput in;
      std::array<bool, 2> composed{};
    };
    const auto whole_part = [&]() {  // composed, or fitted (Sec. 4.3)
      SubregionReport r1, r2;
      Part pt;
      pt.sub1 = subregion(s1, rp.rails[0].rail, rp.rails[0].base, so, &r1);
      pt.sub2 = subregion(s2, rp.rails[1].base, rp.rails[1].rail, so, &r2);
      pt.in.faces = {&s1, &s2};
      pt.in.rail_uv = {rp.rails[0].rail, rp.rails[1].rail};
      pt.in.rail = {spline::iso(pt.sub1, 1, 0.0), spline::iso(pt.sub2, 1, 1.0)};
      pt.in.center = spline::iso(pt.sub1, 1, 1.0);
      pt.composed = {r1.composed, r2.composed};
      return pt;
    };
    // One fillet (its cells and quality) per part.
    const auto make = [&](const Part& pt) {
      const Surface& sub1 = pt.sub1;
      const Surface& sub2 = pt.sub2;
      Fillet f;
      const Surface blend = blending_surface(pt.in, o.blend);
      FilletQuality& q = f.quality;
      q.construction = o.construction;
      if (o.construction == Construction::ruled) {
        const auto halves = ruled_fillet(sub1, sub2, blend);
        f.cells.assign(halves.begin(), halves.end());
      } else if (o.construction == Construction::vbs) {
        const auto cells = vbs_fillet(sub1, sub2, blend, o.vbs, &q.vbs);  // Sec. 3.2, Alg. 3, App. A
        f.cells.assign(cells.begin(), cells.end());
      } else {
        VrepFillet v = vrep_fillet(sub1, sub2, blend, o.vrep, &q.vrep);  // Sec. 5, Alg. 6
        f.cells.push_back(std::move(v.hbs));
        f.beyond.assign(v.beyond.begin(), v.beyond.end());
        f.caps = std::move(v.caps);
      }
      q.composed = pt.composed;
      q.rail_error = {rp.rails[0].max_error, rp.rails[1].max_error};
      q.face[0] = shape(s1);
      q.face[1] = shape(s2);
      q.sub[0] = shape(sub1);
      q.sub[1] = shape(sub2);
      q.blend = shape(blend);
      q.fillet = shape(f.cells[0]);
      for (const auto& c : f.cells) q.cells.push_back(shape(c));
      q.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      measure({&s1, &s2}, blend, f, q);
      return f;
    };
    const bool crossing = crosses_knot_lines(s1, rp.rails[0].rail) || crosses_knot_lines(s1, rp.rails[0].base) ||
                          crosses_knot_lines(s2, rp.rails[1].rail) || crosses_knot_lines(s2, rp.rails[1].base);
    std::vector<Fillet> made;
    if (o.method == SubregionMethod::matched || (o.method == SubregionMethod::automatic && crossing)) {
      try {
        for (auto& mp : matched_pieces(s1, s2, rp, matched_cuts(s1, s2, rp))) {
          made.push_back(make(Part{std::move(mp.sub1), std::move(mp.sub2), std::move(mp.blend), {true, true}}));
        }
      } catch (const Error& e) {
        // Lemma 1's condition, or a piece's blend, fails: "auto" fits instead (Sec. 4.3).
        if (o.method == SubregionMethod::matched || e.kind() != ErrorKind::failed) throw;
        made.clear();
      }
    }
    if (made.empty()) made.push_back(make(whole_part()));
    for (auto& f : made) {
      f.rails = rp;
      f.component = ci;
      out.push_back(std::move(f));
    }
  }
  return out;
}

}  // namespace trivox::fillet
