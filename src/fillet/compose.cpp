#include "trivox/fillet/compose.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "trivox/construct/constructors.hpp"
#include "fillet_util.hpp"
#include "trivox/error.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/fit.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::fillet {

using spline::Breakpoint;
using spline::Curve;
using spline::KnotVector;
using spline::Surface;
using detail::halved;
using detail::num;

namespace {

/// The space of s o r along one direction of r: degree (p + q) * deg_r, each interior
/// breakpoint of r keeping r's continuity there.
KnotVector composed_knots(const KnotVector& r_knots, int surface_degree_sum) {
  const int deg_r = r_knots.degree();
  const int deg = std::max(1, surface_degree_sum * deg_r);
  std::vector<Breakpoint> breaks = r_knots.breakpoints();
  for (std::size_t i = 1; i + 1 < breaks.size(); ++i) {
    const int continuity = deg_r - breaks[i].multiplicity;
    breaks[i].multiplicity = std::clamp(deg - continuity, 1, deg + 1);
  }
  return KnotVector::from_breakpoints(deg + 1, breaks);
}

void check_map(const Surface& s, int map_dim, bool map_rational, const std::array<std::vector<double>, 2>& box,
               const char* what) {
  if (s.rational() || map_rational)
    throw Error(std::string("composition with a rational ") + (s.rational() ? "surface" : what) +
                "; expected polynomial splines");
  if (map_dim != 2)
    throw Error(std::string("composition: the ") + what + " has " + std::to_string(map_dim) +
                " coordinates; expected 2 (parameters of the surface)");
  for (int d = 0; d < 2; ++d) {
    const auto dom = s.domain(d);
    const double slack = 1e-9 * (dom[1] - dom[0]);
    const double lo = box[0][static_cast<std::size_t>(d)], hi = box[1][static_cast<std::size_t>(d)];
    if (lo < dom[0] - slack || hi > dom[1] + slack)
      throw Error(std::string("composition: the ") + what + " reaches " + (d ? "v" : "u") + " in [" + num(lo) +
                  ", " + num(hi) + "]; expected it within the surface's domain [" + num(dom[0]) + ", " +
                  num(dom[1]) + "]");
  }
}

bool box_crosses(const Surface& s, const std::array<std::vector<double>, 2>& box) {
  for (int d = 0; d < 2; ++d) {
    const auto dom = s.domain(d);
    const double slack = 1e-12 * (dom[1] - dom[0]);
    const auto breaks = s.knots(d).breakpoints();
    for (std::size_t i = 1; i + 1 < breaks.size(); ++i) {
      const double b = breaks[i].value;
      if (box[0][static_cast<std::size_t>(d)] < b - slack && box[1][static_cast<std::size_t>(d)] > b + slack)
        return true;
    }
  }
  return false;
}

void eval_clamped(const Surface& s, const double* uv, double* out) {
  std::array<double, 2> t{};
  for (int d = 0; d < 2; ++d) {
    const auto dom = s.domain(d);
    t[static_cast<std::size_t>(d)] = std::clamp(uv[d], dom[0], dom[1]);
  }
  s.eval(t, out);
}

int degree_sum(const Surface& s) { return (s.orders()[0] - 1) + (s.orders()[1] - 1); }

}  // namespace

bool crosses_knot_lines(const Surface& s, const Curve& c) { return box_crosses(s, spline::bounding_box(c)); }
bool crosses_knot_lines(const Surface& s, const Surface& r) { return box_crosses(s, spline::bounding_box(r)); }

Curve compose(const Surface& s, const Curve& c) {
  const auto box = spline::bounding_box(c);
  check_map(s, c.dim(), c.rational(), box, "curve");
  if (box_crosses(s, box))
    throw Error("composition: the curve crosses an interior knot line of the surface; expected it within one "
                "polynomial piece");
  const KnotVector knots = composed_knots(c.knots(0), degree_sum(s));
  const std::vector<double> g = knots.greville();
  const int dim = s.dim();
  std::vector<double> values(g.size() * static_cast<std::size_t>(dim));
  double uv[2];
  for (std::size_t i = 0; i < g.size(); ++i) {
    c.eval({g[i]}, uv);
    eval_clamped(s, uv, values.data() + i * static_cast<std::size_t>(dim));
  }
  return spline::interpolate_curve(g, dim, values, knots);
}

Surface compose(const Surface& s, const Surface& r) {
  const auto box = spline::bounding_box(r);
  check_map(s, r.dim(), r.rational(), box, "map");
  if (box_crosses(s, box))
    throw Error("composition: the map crosses an interior knot line of the surface; expected it within one "
                "polynomial piece");
  const int sum = degree_sum(s);
  const std::array<KnotVector, 2> knots{composed_knots(r.knots(0), sum), composed_knots(r.knots(1), sum)};
  const std::vector<double> gu = knots[0].greville(), gv = knots[1].greville();
  const int dim = s.dim();
  std::vector<double> values(gu.size() * gv.size() * static_cast<std::size_t>(dim));
  double uv[2];
  for (std::size_t b = 0; b < gv.size(); ++b)
    for (std::size_t a = 0; a < gu.size(); ++a) {
      r.eval({gu[a], gv[b]}, uv);
      eval_clamped(s, uv, values.data() + (a + gu.size() * b) * static_cast<std::size_t>(dim));
    }
  return spline::fit_surface_grid(gu, gv, dim, values, knots);
}

const char* subregion_method_name(SubregionMethod m) noexcept {
  switch (m) {
    case SubregionMethod::compose: return "compose";
    case SubregionMethod::fit: return "fit";
    case SubregionMethod::automatic: return "auto";
    case SubregionMethod::matched: return "matched";
  }
  return "?";
}

bool subregion_method_from_name(const char* name, SubregionMethod& out) noexcept {
  for (SubregionMethod m : {SubregionMethod::compose, SubregionMethod::fit, SubregionMethod::automatic, SubregionMethod::matched})
    if (std::strcmp(name, subregion_method_name(m)) == 0) {
      out = m;
      return true;
    }
  return false;
}

namespace {

/// Parameters for least-squares data along a knot vector: `per_span` interior points in every
/// non-empty span plus the ends (enough for any free control point to see data).
std::vector<double> sample_params(const KnotVector& k, int per_span) {
  std::vector<double> t;
  const auto breaks = k.breakpoints();
  for (std::size_t i = 0; i + 1 < breaks.size(); ++i) {
    const double a = breaks[i].value, b = breaks[i + 1].value;
    for (int j = 0; j < per_span; ++j) t.push_back(a + (b - a) * j / per_span);
  }
  t.push_back(breaks.back().value);
  return t;
}

double xyz_distance(const double* a, const double* b, int dim) {
  double s = 0.0;
  for (int c = 0; c < std::min(3, dim); ++c) s += (a[c] - b[c]) * (a[c] - b[c]);
  return std::sqrt(s);
}

/// Masalha et al. 2021, Sec. 4.3: the sub-region as a least-squares surface of samples of s(r),
/// with the boundary rows v = 0 and v = 1 pinned to least-squares curves of s(from) and s(to).
Surface fit_subregion(const Surface& s, const Surface& r, const SubregionOptions& o, double& error) {
  const int dim = s.dim();
  // u: cubic on the curves' breakpoints; v: a cubic Bezier, then halved with u.
  std::vector<Breakpoint> breaks = r.knots(0).breakpoints();
  for (std::size_t i = 1; i + 1 < breaks.size(); ++i) breaks[i].multiplicity = 1;
  KnotVector ku = KnotVector::from_breakpoints(4, breaks);
  KnotVector kv = KnotVector::bezier(4, r.domain(1)[0], r.domain(1)[1]);
  std::vector<double> p(dim), q(dim), uv(2);
  const auto image = [&](double u, double v, double* out) {
    r.eval({u, v}, uv.data());
    eval_clamped(s, uv.data(), out);
  };
  for (int round = 0; round < o.max_rounds; ++round) {
    const std::vector<double> us = sample_params(ku, 4), vs = sample_params(kv, 6);
    std::vector<double> grid(us.size() * vs.size() * static_cast<std::size_t>(dim));
    for (std::size_t b = 0; b < vs.size(); ++b)
      for (std::size_t a = 0; a < us.size(); ++a) image(us[a], vs[b], grid.data() + (a + us.size() * b) * dim);
    spline::SurfacePins pins;
    for (int side = 0; side < 2; ++side) {
      const std::size_t b = side ? vs.size() - 1 : 0;
      std::vector<double> row(grid.begin() + static_cast<std::ptrdiff_t>(us.size() * b * dim),
                              grid.begin() + static_cast<std::ptrdiff_t>(us.size() * (b + 1) * dim));
      pins.curves[side ? spline::SurfacePins::v1 : spline::SurfacePins::v0] = spline::fit_curve(us, dim, row, ku);
    }
    Surface fitted = spline::fit_surface_grid(us, vs, dim, grid, {ku, kv}, pins);
    // Check between the data: half-way along u (at the v samples) and along v (at the u
    // samples); each direction is refined only where its own check fails.
    double err_u = 0.0, err_v = 0.0;
    for (std::size_t b = 0; b < vs.size(); ++b)
      for (std::size_t a = 0; a < us.size(); ++a) {
        if (a + 1 < us.size()) {
          image(0.5 * (us[a] + us[a + 1]), vs[b], p.data());
          fitted.eval({0.5 * (us[a] + us[a + 1]), vs[b]}, q.data());
          err_u = std::max(err_u, xyz_distance(p.data(), q.data(), dim));
        }
        if (b + 1 < vs.size()) {
          image(us[a], 0.5 * (vs[b] + vs[b + 1]), p.data());
          fitted.eval({us[a], 0.5 * (vs[b] + vs[b + 1])}, q.data());
          err_v = std::max(err_v, xyz_distance(p.data(), q.data(), dim));
        }
      }
    error = std::max(err_u, err_v);
    if (error <= o.tolerance) return fitted;
    if (err_u > o.tolerance) ku = halved(ku);
    if (err_v > o.tolerance) kv = halved(kv);
  }
  throw Error("fillet sub-region: the least-squares fit is " + num(error) + " from the surface after " +
                  std::to_string(o.max_rounds) + " refinements; expected at most " + num(o.tolerance),
              ErrorKind::failed);
}

}  // namespace

Surface subregion(const Surface& s, const Curve& from, const Curve& to, const SubregionOptions& options,
                  SubregionReport* report) {
  if (!(from.knots(0) == to.knots(0)))
    throw Error("fillet sub-region: the two boundary curves are in different function spaces; expected the "
                "same order and knots");
  if (!(options.tolerance > 0.0) || !std::isfinite(options.tolerance))
    throw Error("fillet sub-region: tolerance " + num(options.tolerance) + "; expected a positive value");
  const Surface r = construct::ruled(from, to);
  check_map(s, r.dim(), r.rational(), spline::bounding_box(r), "ruled map");
  const bool crosses = box_crosses(s, spline::bounding_box(r));
  if (crosses && (options.method == SubregionMethod::compose || options.method == SubregionMethod::matched))
    throw Error("fillet sub-region: the region between the curves crosses knot lines of the surface, where exact "
                "composition is no tensor-product spline; expected method \"fit\" or \"auto\"");
  SubregionReport rep;
  Surface out;
  if (options.method == SubregionMethod::fit || crosses) {
    out = fit_subregion(s, r, options, rep.fit_error);
  } else {
    out = compose(s, r);
    rep.composed = true;
  }
  if (report) *report = rep;
  return out;
}

}  // namespace trivox::fillet
