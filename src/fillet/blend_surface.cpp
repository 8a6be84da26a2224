#include "trivox/fillet/blend_surface.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "trivox/construct/constructors.hpp"
#include "fillet_util.hpp"
#include "trivox/error.hpp"
#include "trivox/spline/fit.hpp"

namespace trivox::fillet {

using spline::Breakpoint;
using spline::Curve;
using spline::KnotVector;
using spline::Surface;
using detail::Vec;
using namespace detail;

const char* section_name(Section s) noexcept { return s == Section::hermite ? "hermite" : "flend"; }

bool section_from_name(const char* name, Section& out) noexcept {
  for (Section s : {Section::hermite, Section::flend})
    if (std::strcmp(name, section_name(s)) == 0) {
      out = s;
      return true;
    }
  return false;
}

namespace {

/// The point (and derivative) of a curve in R^>=3 at t, xyz only.
void curve_at(const Curve& c, double t, Vec& p, Vec* d = nullptr) {
  std::vector<double> out(static_cast<std::size_t>(2 * c.dim()));
  c.eval_derivatives({t}, d ? 1 : 0, out.data());
  for (int k = 0; k < 3; ++k) p[static_cast<std::size_t>(k)] = out[static_cast<std::size_t>(k)];
  if (d)
    for (int k = 0; k < 3; ++k) (*d)[static_cast<std::size_t>(k)] = out[static_cast<std::size_t>(c.dim() + k)];
}

/// Unit normal S_u x S_v of face at the rail's parameters at t.
Vec face_normal(const Surface& face, const Curve& rail_uv, double t) {
  double uv[2];
  rail_uv.eval({t}, uv);
  const auto dom_u = face.domain(0), dom_v = face.domain(1);
  const std::array<double, 2> p{std::clamp(uv[0], dom_u[0], dom_u[1]), std::clamp(uv[1], dom_v[0], dom_v[1])};
  std::vector<double> out(static_cast<std::size_t>(3 * face.dim()));
  face.eval_derivatives(p, 1, out.data());
  const std::size_t k = static_cast<std::size_t>(face.dim());
  const Vec su{out[k], out[k + 1], out[k + 2]}, sv{out[2 * k], out[2 * k + 1], out[2 * k + 2]};
  const Vec n = cross(su, sv);
  const double len = norm(n);
  if (!(len > 0.0))
    throw Error("blending surface: the primary surface is singular (zero normal) on the rail at t = " + num(t),
                ErrorKind::failed);
  return scale(n, 1.0 / len);
}

/// Greville parameters of a cubic on the given breakpoints (simple interior knots).
KnotVector cubic_on(std::vector<Breakpoint> breaks) {
  for (std::size_t i = 1; i + 1 < breaks.size(); ++i) breaks[i].multiplicity = 1;
  return KnotVector::from_breakpoints(4, breaks);
}

/// A field along t in R^3 interpolated at the Greville points of `start`, its spans halved until
/// `error(t, value)` (angles) is within tolerance between the samples.
Curve fit_field(const std::function<Vec(double)>& exact, const std::function<std::array<double, 2>(double, const Vec&)>& error,
                const KnotVector& start, const BlendOptions& o, BlendReport& rep) {
  KnotVector k = start;
  for (int round = 0; round <= o.max_rounds; ++round) {
    const std::vector<double> g = k.greville();
    std::vector<double> values;
    values.reserve(3 * g.size());
    for (double t : g) {
      const Vec v = exact(t);
      values.insert(values.end(), v.begin(), v.end());
    }
    Curve c = spline::interpolate_curve(g, 3, values, k);
    std::array<double, 2> worst{0.0, 0.0};
    // Spans where the field misses the tolerance: only those are halved (with their neighbours,
    // so that knot spacing stays graded). Halving everything doubled a thousand-span rail's
    // field per round, to hundreds of thousands of knots where a face's normal turns fast (a
    // merged patch join): local refinement keeps the growth at the trouble spots.
    const auto br = k.breakpoints();
    std::vector<char> bad(br.size() > 1 ? br.size() - 1 : 0, 0);
    for (std::size_t i = 0; i + 1 < g.size(); ++i)
      for (double f : {0.25, 0.5, 0.75}) {
        const double t = g[i] + f * (g[i + 1] - g[i]);
        Vec v;
        c.eval({t}, v.data());
        const auto e = error(t, v);
        worst[0] = std::max(worst[0], e[0]);
        worst[1] = std::max(worst[1], e[1]);
        if (e[0] > o.angle_tolerance || e[1] > o.angle_tolerance) {
          const auto at = std::upper_bound(br.begin(), br.end(), t, [](double x, const spline::Breakpoint& b) { return x < b.value; });
          const auto span = static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(at - br.begin() - 1, 0, static_cast<std::ptrdiff_t>(bad.size()) - 1));
          for (std::size_t q = span > 0 ? span - 1 : 0; q <= std::min(span + 1, bad.size() - 1); ++q) bad[q] = 1;
        }
      }
    if (worst[0] <= o.angle_tolerance && worst[1] <= o.angle_tolerance) {
      rep.angle = worst;
      rep.rounds = std::max(rep.rounds, round);
      return c;
    }
    std::vector<double> all = k.knots();
    for (std::size_t q = 0; q < bad.size(); ++q)
      if (bad[q]) all.push_back(0.5 * (br[q].value + br[q + 1].value));
    std::sort(all.begin(), all.end());
    k = KnotVector(k.order(), all);
  }
  throw Error("blending surface: the tangent field does not reach the angle tolerance " + num(o.angle_tolerance) +
                  " rad after " + std::to_string(o.max_rounds) + " refinements",
              ErrorKind::failed);
}

/// Angle between vector x and the plane with unit normal n.
double off_plane(const Vec& x, const Vec& n) {
  const double len = norm(x);
  return len > 0.0 ? std::asin(std::min(1.0, std::abs(dot(x, n)) / len)) : 0.0;
}

Curve xyz_of(const Curve& c) {
  if (c.dim() == 3) return c;
  std::vector<double> pts;
  for (int i = 0; i < c.size(); ++i) {
    const auto p = c.point(i);
    pts.insert(pts.end(), p.begin(), p.begin() + 3);
  }
  return Curve({c.knots(0)}, 3, std::move(pts));
}

}  // namespace

Surface blending_surface(const BlendInput& in, const BlendOptions& o, BlendReport* report) {
  if (o.section == Section::hermite && !(o.tau > 0.0 && o.tau <= 10.0))
    throw Error("blending surface: tau " + num(o.tau) + "; expected a value in (0, 10]");
  if (o.section == Section::flend && !(o.dip >= 0.0 && o.dip <= 1.0))
    throw Error("blending surface: dip " + num(o.dip) + "; expected a value in [0, 1]");
  if (!(o.angle_tolerance > 0.0)) throw Error("blending surface: angle tolerance must be positive");
  for (int i = 0; i < 2; ++i) {
    if (!in.faces[static_cast<std::size_t>(i)] || in.faces[static_cast<std::size_t>(i)]->dim() < 3)
      throw Error("blending surface: face " + std::to_string(i + 1) + " missing or not in R^3");
    if (in.rail_uv[static_cast<std::size_t>(i)].dim() != 2 || in.rail[static_cast<std::size_t>(i)].dim() < 3)
      throw Error("blending surface: rail " + std::to_string(i + 1) + " needs parameters in R^2 and points in R^3");
  }
  if (in.center.dim() < 3) throw Error("blending surface: the intersection curve must be in R^3");

  const std::array<Curve, 2> rail{xyz_of(in.rail[0]), xyz_of(in.rail[1])};
  const Curve center = xyz_of(in.center);
  // The field is interpolated in the rails' own space (for composed sub-regions a high degree on
  // the rails' breakpoints, dense enough as it is), so S_b's space along t is the rails' space
  // and needs no union of knots; where that is a cubic on few spans, halving refines it.
  const KnotVector start = rail[0].knots(0).order() >= 4 ? rail[0].knots(0) : cubic_on(rail[0].knots(0).breakpoints());
  BlendReport rep;
  std::vector<Curve> rows;
  KnotVector across;

  if (o.section == Section::hermite) {
    // Masalha et al. 2021, Sec. 1.3: T_i = C_i^r' x N_i(c_i^r), normalised,
    // scaled by tau |C_1 - C_2|.
    std::array<Curve, 2> field;
    for (int i = 0; i < 2; ++i) {
      const Surface& face = *in.faces[static_cast<std::size_t>(i)];
      const Curve& ruv = in.rail_uv[static_cast<std::size_t>(i)];
      const auto exact = [&, i](double t) {
        Vec p, dp, q, c;
        curve_at(rail[static_cast<std::size_t>(i)], t, p, &dp);
        curve_at(rail[static_cast<std::size_t>(1 - i)], t, q);
        curve_at(center, t, c);
        const Vec n = face_normal(face, ruv, t);
        // Towards C for rail 1, away from C for rail 2 (the v direction of S_b).
        const Vec toward = i == 0 ? sub(c, p) : sub(p, c);
        Vec dir = cross(dp, n);
        if (norm(dir) <= 1e-10 * norm(toward))
          dir = sub(toward, scale(n, dot(toward, n)));  // rail standing still (trimmed): across C
        if (dot(dir, toward) < 0.0) dir = scale(dir, -1.0);
        const double len = norm(dir), width = norm(sub(p, q));
        if (!(len > 0.0) || !(width > 0.0))
          throw Error("blending surface: the rails meet or the tangent field vanishes at t = " + num(t),
                      ErrorKind::failed);
        return scale(dir, o.tau * width / len);
      };
      const auto error = [&](double t, const Vec& v) -> std::array<double, 2> {
        const Vec e = exact(t);
        // The magnitude only shapes S_b: 1e-3 relative is plenty; expressed on the angle's scale.
        constexpr double magnitude_tolerance = 1e-3;
        const double rel = norm(sub(v, e)) / std::max(norm(e), 1e-300);
        return {off_plane(v, face_normal(face, ruv, t)), rel * o.angle_tolerance / magnitude_tolerance};
      };
      BlendReport r;
      field[static_cast<std::size_t>(i)] = fit_field(exact, error, start, o, r);
      rep.angle[static_cast<std::size_t>(i)] = r.angle[0];
      rep.rounds = std::max(rep.rounds, r.rounds);
    }
    const std::vector<Curve> parts{rail[0], rail[1], field[0], field[1]};
    const std::vector<Curve> c = construct::common_space<1>(parts);
    // Bezier rows of the cubic Hermite in v: C_1, C_1 + T_1 / 3, C_2 - T_2 / 3, C_2.
    Curve r1 = c[0], r2 = c[1];
    for (int j = 0; j < r1.size(); ++j)
      for (int k = 0; k < 3; ++k) {
        r1.point(j)[static_cast<std::size_t>(k)] += c[2].point(j)[static_cast<std::size_t>(k)] / 3.0;
        r2.point(j)[static_cast<std::size_t>(k)] -= c[3].point(j)[static_cast<std::size_t>(k)] / 3.0;
      }
    rows = {c[0], r1, r2, c[1]};
    across = KnotVector::bezier(4);
  } else {
    // Flends Sec. II.A: P_I from three planes, then five control points affine in C_1, C_2, P_I.
    const auto exact = [&](double t) {
      Vec a, b, c, dc;
      curve_at(rail[0], t, a);
      curve_at(rail[1], t, b);
      curve_at(center, t, c, &dc);
      const Vec n1 = face_normal(*in.faces[0], in.rail_uv[0], t), n2 = face_normal(*in.faces[1], in.rail_uv[1], t);
      const double lc = norm(dc);
      if (!(lc > 0.0)) throw Error("flend: the intersection curve has no tangent at t = " + num(t), ErrorKind::failed);
      const Vec n3 = scale(dc, 1.0 / lc);
      // Cramer: x = (d1 (n2 x n3) + d2 (n3 x n1) + d3 (n1 x n2)) / (n1 . (n2 x n3)).
      const double det = dot(n1, cross(n2, n3));
      if (std::abs(det) < 1e-9)
        throw Error("flend: the tangent planes at the rails and the normal plane of C are nearly parallel at t = " +
                        num(t) + " (determinant " + num(det) + ")",
                    ErrorKind::failed);
      const double d1 = dot(n1, a), d2 = dot(n2, b), d3 = dot(n3, c);
      return scale(axpy(axpy(scale(cross(n2, n3), d1), d2, cross(n3, n1)), d3, cross(n1, n2)), 1.0 / det);
    };
    const auto error = [&](double t, const Vec& pi) -> std::array<double, 2> {
      Vec a, b;
      curve_at(rail[0], t, a);
      curve_at(rail[1], t, b);
      return {off_plane(sub(pi, a), face_normal(*in.faces[0], in.rail_uv[0], t)),
              off_plane(sub(pi, b), face_normal(*in.faces[1], in.rail_uv[1], t))};
    };
    const Curve pi_fit = fit_field(exact, error, start, o, rep);
    const std::vector<Curve> parts{rail[0], rail[1], pi_fit};
    const std::vector<Curve> c = construct::common_space<1>(parts);
    const double d = o.dip;
    rows.assign(5, c[0]);
    for (int j = 0; j < c[0].size(); ++j) {
      Vec p0, p4, pi;
      for (int k = 0; k < 3; ++k) {
        p0[static_cast<std::size_t>(k)] = c[0].point(j)[static_cast<std::size_t>(k)];
        p4[static_cast<std::size_t>(k)] = c[1].point(j)[static_cast<std::size_t>(k)];
        pi[static_cast<std::size_t>(k)] = c[2].point(j)[static_cast<std::size_t>(k)];
      }
      const Vec p1 = axpy(p0, d, sub(pi, p0)), p3 = axpy(p4, d, sub(pi, p4));
      const Vec ps = axpy(p1, d, sub(pi, p1)), pss = axpy(p3, d, sub(pi, p3));
      const Vec p2 = scale(axpy(ps, 1.0, pss), 0.5);
      const Vec all[5] = {p0, p1, p2, p3, p4};
      for (int r = 0; r < 5; ++r)
        for (int k = 0; k < 3; ++k)
          rows[static_cast<std::size_t>(r)].point(j)[static_cast<std::size_t>(k)] = all[r][static_cast<std::size_t>(k)];
    }
    across = KnotVector(4, {0, 0, 0, 0, 0.5, 1, 1, 1, 1});
  }
  if (report) *report = rep;
  return construct::stack<2>(rows, 1, across);
}

}  // namespace trivox::fillet
