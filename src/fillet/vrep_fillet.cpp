#include "trivox/fillet/vrep_fillet.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "fillet_util.hpp"
#include "property_blend.hpp"
#include "trivox/construct/constructors.hpp"
#include "trivox/error.hpp"
#include "trivox/geom/closest_point.hpp"
#include "trivox/spline/calculus.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/fit.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::fillet {

using spline::Curve;
using spline::Face;
using spline::Surface;
using spline::Trivariate;
using detail::num;
using detail::row;
using detail::Vec;

namespace {

/// The parameters of the point of t nearest p: projected Gauss-Newton on X(uvw) = p, clamped to
/// t's domain, from `start`. Returns |X(uvw) - p|: 0 (to rounding) when p is in t's image near
/// start, else about the distance from p to the part of the boundary Newton stopped on.
double invert(const Trivariate& t, const Vec& p, std::array<double, 3> uvw) {
  const std::size_t k = static_cast<std::size_t>(t.dim());
  std::vector<double> d(4 * k);
  double res = std::numeric_limits<double>::infinity();
  for (int it = 0; it < 40; ++it) {
    t.eval_derivatives(uvw, 1, d.data());
    const Vec r = detail::sub(detail::xyz(d.data()), p);
    res = detail::norm(r);
    if (res < 1e-14) break;
    const Vec a = detail::xyz(d.data() + k), b = detail::xyz(d.data() + 2 * k), c = detail::xyz(d.data() + 3 * k);
    const double det = detail::dot(a, detail::cross(b, c));
    if (!(std::abs(det) > 0.0)) break;
    // Cramer's rule for [a b c] s = -r.
    const Vec s{-detail::dot(r, detail::cross(b, c)) / det, -detail::dot(a, detail::cross(r, c)) / det,
                -detail::dot(a, detail::cross(b, r)) / det};
    double step = 0.0;
    for (std::size_t j = 0; j < 3; ++j) {
      const auto dom = t.domain(static_cast<int>(j));
      const double next = std::clamp(uvw[j] + s[j], dom[0], dom[1]);
      step = std::max(step, std::abs(next - uvw[j]));
      uvw[j] = next;
    }
    if (step < 1e-15) break;
  }
  t.eval_derivatives(uvw, 0, d.data());
  return detail::norm(detail::sub(detail::xyz(d.data()), p));
}

/// Alg. 6 lines 8-11: the trimming curve C_Sb of the cap T_hbs(e, v, w), the curve where the
/// solid beyond S_b meets it, in the cap's (v, w): S_b's end section projected on the cap (65
/// samples, warm-started Newton from rail 1 at (v, w) = (1, 0)), interpolated by a cubic.
/// `gap` grows to the largest distance of the section from the cap.
vmodel::FaceTrim cap_trim(const Trivariate& hbs, const Surface& blend, Face face, double& gap) {
  const Surface cap = spline::boundary_face(hbs, face);
  const geom::SurfaceDistance to_cap(spline::coordinates(cap, 0, 3), 2);
  const Curve section = spline::iso(blend, 0, face == Face::u0 ? 0.0 : 1.0);
  constexpr int n = 65;
  std::vector<double> params(n), uv(2 * n);
  std::array<double, 2> start{1.0, 0.0};
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / (n - 1);
    const auto x = section.eval({s});
    const auto cp = to_cap.closest({x[0], x[1], x[2]}, start);
    gap = std::max(gap, cp.distance);
    params[static_cast<std::size_t>(i)] = s;
    uv[2 * static_cast<std::size_t>(i)] = cp.uv[0];
    uv[2 * static_cast<std::size_t>(i) + 1] = cp.uv[1];
    start = cp.uv;
  }
  vmodel::FaceTrim trim;
  trim.face = face;
  trim.curves.push_back(spline::interpolate_curve(params, 2, uv, 4));
  return trim;
}

}  // namespace

vmodel::VCell VrepFillet::cell(const std::string& name) const {
  vmodel::VCell c(name, hbs);
  c.without.push_back({vmodel::VCell(name + ".beyond.1", beyond[0]), vmodel::VCell(name + ".beyond.2", beyond[1])});
  c.trim_curves = caps;
  return c;
}

VrepFillet vrep_fillet(const Surface& sub1, const Surface& sub2, const Surface& blend, const VrepOptions& options,
                       VrepReport* report) {
  if (!(options.tolerance > 0.0))
    throw Error("V-rep fillet: tolerance " + num(options.tolerance) + "; expected a value > 0");
  auto [s1, s2, b] = detail::fillet_common_space(sub1, sub2, blend, "V-rep fillet");
  const int k = s1.dim(), nv = s1.count(1);
  const auto box = b.control_box();
  const double size = std::hypot(box[1][0] - box[0][0], box[1][1] - box[0][1], box[1][2] - box[0][2]);
  const double tol = options.tolerance * size;

  // Boundaries that must coincide, joined exactly: C twice (xyz), S_b's rails and S^_i's.
  VrepReport rep;
  rep.rail_gap = {detail::curve_gap(row(b, 0), row(s1, 0)), detail::curve_gap(row(b, nv - 1), row(s2, nv - 1))};
  for (int m = 0; m < s1.count(0); ++m) {
    const auto p = s1.point(s1.row({m, nv - 1})), q = s2.point(s2.row({m, 0}));
    for (std::size_t j = 3; j < static_cast<std::size_t>(k); ++j)
      rep.property_jump = std::max(rep.property_jump, std::abs(p[j] - q[j]));
  }
  rep.c_gap = detail::join_at_c(s1, s2);
  if (!(rep.c_gap <= tol))
    throw Error("V-rep fillet: S^_1(u, 1) and S^_2(u, 0) are " + num(rep.c_gap) +
                " apart; expected the same curve C (within " + num(tol) + ")");
  for (int i = 0; i < 2; ++i)
    if (!(rep.rail_gap[static_cast<std::size_t>(i)] <= tol))
      throw Error("V-rep fillet: the blending surface's rail " + std::to_string(i + 1) + " is " +
                  num(rep.rail_gap[static_cast<std::size_t>(i)]) + " from S^_" + std::to_string(i + 1) +
                  "'s; expected the same curve (within " + num(tol) + ")");
  detail::set_row(b, 0, row(s1, 0), k);
  detail::set_row(b, nv - 1, row(s2, nv - 1), k);

  // Def. 5.1 with v from C: a(u, v) = S^_1(u, 1 - v), so a(u, 0) = S^_2(u, 0) = C.
  const Surface a = spline::reverse(s1, 1);
  Trivariate T = construct::half_boolean_sum(a, s2);  // Alg. 6 line 2; C's properties: the mean
  if (T.knots(0) != a.knots(0) || T.knots(1) != a.knots(1) || T.knots(2) != s2.knots(1))
    throw Error("V-rep fillet: the half Boolean sum left the sub-regions' spaces (internal)", ErrorKind::failed);
  // Lemma 2 in the properties too: the faces carry g_1 and g_2 exactly, except on C (the mean).
  Curve C = row(a, 0);
  {
    const Curve c2 = row(s2, 0);
    for (int m = 0; m < C.size(); ++m) {
      auto p = C.point(m);
      const auto q = c2.point(m);
      for (std::size_t j = 3; j < static_cast<std::size_t>(k); ++j) p[j] = 0.5 * (p[j] + q[j]);
    }
  }
  detail::set_layer(T, 2, 0, a, "V-rep fillet");
  detail::set_layer(T, 1, 0, s2, "V-rep fillet");
  for (int m = 0; m < C.size(); ++m) {
    const auto q = C.point(m);
    auto p = T.point(T.row({m, 0, 0}));
    std::copy(q.begin(), q.end(), p.begin());
  }
  if (detail::jacobian_at(T, {0.5, 0.5, 0.5}) < 0.0) {
    T = spline::reverse(T, 0);
    b = spline::reverse(b, 0);
    rep.reversed = true;
  }

  // The solid beyond S_b: ruled between S_b and T_hbs's far faces, split where S_b is nearest to
  // C (Eq. A.1's projection of C(1/2), as the VBS division): the section bends towards C, so that
  // point is inside, and the ruling from it to the far corner K splits the solid in two.
  const Surface F1 = spline::boundary_face(T, Face::v1);                    // T(u, 1, w): rail 1 -> K
  const Surface F2 = spline::reverse(spline::boundary_face(T, Face::w1), 1);  // T(u, 1 - v, 1): K -> rail 2
  rep.v_b = detail::project(spline::iso(b, 0, 0.5), detail::xyz_at(C, 0.5));
  if (!(rep.v_b > 1e-6 && rep.v_b < 1.0 - 1e-6))
    throw Error("V-rep fillet: the projection of C(1/2) on S_b(1/2, v) lands at v = " + num(rep.v_b) +
                    ", a rail; expected a point inside (a blending surface that bends towards C)",
                ErrorKind::failed);
  auto [ba, bb] = detail::split_across(b, rep.v_b);
  VrepFillet out;
  out.beyond = {construct::ruled(ba, F1), construct::ruled(bb, F2)};
  for (std::size_t i = 0; i < 2; ++i) {
    rep.beyond_jacobian[i] = detail::sampled_jacobian(out.beyond[i]);
    const auto& r = rep.beyond_jacobian[i];
    if (!((r[0] > 0.0 && r[1] > 0.0) || (r[0] < 0.0 && r[1] < 0.0)))
      throw Error("V-rep fillet: det J of the solid beyond S_b (part " + std::to_string(i + 1) + ") ranges over [" +
                      num(r[0]) + ", " + num(r[1]) +
                      "]; expected one sign (S_b folds against the half Boolean sum's far faces)",
                  ErrorKind::failed);
    rep.beyond_volume[i] = std::abs(detail::boundary_volume(out.beyond[i]));
  }
  rep.hbs_volume = std::abs(detail::boundary_volume(T));

  // Alg. 6 lines 4-12: caps for an open C (T_hbs's end faces apart).
  double ends = 0.0;
  for (int j = 0; j < T.count(1); ++j)
    for (int l = 0; l < T.count(2); ++l)
      ends = std::max(ends, detail::distance3(T.point(T.row({0, j, l})), T.point(T.row({T.count(0) - 1, j, l}))));
  rep.closed = ends <= tol;
  if (!rep.closed)
    for (const Face face : {Face::u0, Face::u1}) out.caps.push_back(cap_trim(T, b, face, rep.cap_gap));

  // S_b inside T_hbs: invert samples of S_b, starting from the section's matching corner mix (on
  // a closed C a section at the seam may lie just across it: from either end).
  constexpr int nu = 32, ns = 16;
  for (int i = 0; i <= nu; ++i)
    for (int j = 0; j <= ns; ++j) {
      const double u = static_cast<double>(i) / nu, s = static_cast<double>(j) / ns;
      const auto x = b.eval({u, s});
      const Vec p{x[0], x[1], x[2]};
      double d = invert(T, p, {u, 1.0 - s, s});
      if (rep.closed && (i == 0 || i == nu)) d = std::min(d, invert(T, p, {1.0 - u, 1.0 - s, s}));
      rep.outside = std::max(rep.outside, d);
    }
  out.hbs = std::move(T);
  if (report) *report = std::move(rep);
  return out;
}

}  // namespace trivox::fillet
