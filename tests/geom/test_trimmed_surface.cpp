// Untrimming of trimmed surfaces (geom/trimmed_surface.hpp). Truths:
// - a planar B-spline face (an affine image of its parameters) trimmed by a polygon with a
//   polygonal hole has the area |a x b| (A_outer - A_hole) from the shoelace formula, and a
//   linear property f = c0 + c1 u + c2 v integrates to |a x b| (c0 A + c1 M_u + c2 M_v) with the
//   polygon's first moments;
// - the patches tile the trimmed domain: a random parameter point inside it (crossing number
//   against the polygon, winding number against a dense polyline of a curved loop) lies in
//   exactly one quad (found by Newton inversion of the quad maps), one outside in none, and
//   every point of a quad's image lies in the domain;
// - neighbouring patches meet: a point of a quad side away from the trimming loops lies on
//   another quad, and both patches give the same point of space there;
// - a bicubic surface trimmed by cubic B-spline loops crossing its knot lines: the patches'
//   area equals -(loop integral of F du) with F(u, v) = int_0^v |S_u x S_v| dw (Green's theorem,
//   computed by Gauss quadrature along the loops, independent of any tiling), and each patch is
//   S(q(s, t)) at random points; a cubic quarter cylinder's trimmed area is
//   -(loop integral of |c'(u)| v du), its area element being |c'(u)|;
// - a polygon along knot lines and a crescent between quadratic arcs give their areas by the
//   shoelace formula and by Green's theorem for quadratic Bezier arcs;
// - refusals: open loop, loop leaving the rectangle, crossing loops, no outer loop, nested
//   outer loops, orders over the limits, a rational surface.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <utility>
#include <vector>

#include "trivox/error.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/geom/trimmed_surface.hpp"
#include "trivox/spline/refine.hpp"

using namespace trivox;
using geom::TrimLoop;
using geom::TrimmedSurface;
using spline::Curve;
using spline::KnotVector;
using spline::Surface;

namespace {

using Pt = std::array<double, 2>;

Curve line(Pt a, Pt b) { return Curve({KnotVector::bezier(2)}, 2, std::vector<double>{a[0], a[1], b[0], b[1]}); }

TrimLoop polygon_loop(const std::vector<Pt>& p) {
  TrimLoop l;
  for (std::size_t i = 0; i < p.size(); ++i) l.pieces.push_back(line(p[i], p[(i + 1) % p.size()]));
  return l;
}

double shoelace(const std::vector<Pt>& p) {
  double a = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto& q = p[i];
    const auto& r = p[(i + 1) % p.size()];
    a += q[0] * r[1] - r[0] * q[1];
  }
  return 0.5 * a;
}

/// First moments int u dA, int v dA of a polygon (signed like its area).
std::array<double, 2> moments(const std::vector<Pt>& p) {
  double mu = 0, mv = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto& q = p[i];
    const auto& r = p[(i + 1) % p.size()];
    const double c = q[0] * r[1] - r[0] * q[1];
    mu += (q[0] + r[0]) * c;
    mv += (q[1] + r[1]) * c;
  }
  return {mu / 6.0, mv / 6.0};
}

bool in_polygon(const std::vector<Pt>& p, Pt x) {
  bool in = false;
  for (std::size_t i = 0, j = p.size() - 1; i < p.size(); j = i++)
    if ((p[i][1] > x[1]) != (p[j][1] > x[1]) &&
        x[0] < (p[j][0] - p[i][0]) * (x[1] - p[i][1]) / (p[j][1] - p[i][1]) + p[i][0])
      in = !in;
  return in;
}

double segment_distance(Pt a, Pt b, Pt x) {
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  double t = ((x[0] - a[0]) * dx + (x[1] - a[1]) * dy) / (dx * dx + dy * dy);
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(a[0] + t * dx - x[0], a[1] + t * dy - x[1]);
}

double polyline_distance(const std::vector<Pt>& p, Pt x, bool closed = true) {
  double d = 1e300;
  const std::size_t n = closed ? p.size() : p.size() - 1;
  for (std::size_t i = 0; i < n; ++i) d = std::min(d, segment_distance(p[i], p[(i + 1) % p.size()], x));
  return d;
}

/// Winding number of a closed polyline around x.
int winding(const std::vector<Pt>& p, Pt x) {
  int w = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Pt& a = p[i];
    const Pt& b = p[(i + 1) % p.size()];
    const double c = (b[0] - a[0]) * (x[1] - a[1]) - (x[0] - a[0]) * (b[1] - a[1]);
    if (a[1] <= x[1]) {
      if (b[1] > x[1] && c > 0) ++w;
    } else if (b[1] <= x[1] && c < 0) {
      --w;
    }
  }
  return w;
}

/// The (s, t) in [0, 1]^2 with q(s, t) = x (to 1e-11), by Newton from a grid of starts; false
/// when there is none.
bool invert(const Surface& q, Pt x, std::array<double, 2>& st) {
  const auto box = q.control_box();
  if (x[0] < box[0][0] - 1e-9 || x[0] > box[1][0] + 1e-9 || x[1] < box[0][1] - 1e-9 || x[1] > box[1][1] + 1e-9)
    return false;
  for (int a = 0; a < 5; ++a)
    for (int b = 0; b < 5; ++b) {
      double s = 0.1 + 0.2 * a, t = 0.1 + 0.2 * b;
      for (int it = 0; it < 60; ++it) {
        const auto d = q.eval_derivatives({s, t}, 1);  // x y, x_s y_s, x_t y_t
        const double fx = d[0] - x[0], fy = d[1] - x[1];
        if (std::hypot(fx, fy) < 1e-14) break;
        const double det = d[2] * d[5] - d[4] * d[3];
        if (det == 0.0) break;
        const double ds = (fx * d[5] - fy * d[4]) / det, dt = (d[2] * fy - d[3] * fx) / det;
        // Evaluation clamps to the domain, so Newton stays in it too: a point outside the quad
        // leaves a residual on the square's boundary.
        s = std::clamp(s - ds, 0.0, 1.0);
        t = std::clamp(t - dt, 0.0, 1.0);
      }
      const auto v = q.eval({s, t});
      if (std::hypot(v[0] - x[0], v[1] - x[1]) < 1e-11) {
        st = {s, t};
        return true;
      }
    }
  return false;
}

/// A B-spline surface reproducing the affine map (u, v) -> o + u a + v b, with a 4th coordinate
/// f = c0 + c1 u + c2 v, on [0, 2] x [0, 1], quadratic, 3 x 2 spans (control points at the
/// Greville abscissae reproduce linear functions exactly).
Surface affine_face(std::array<double, 3> o, std::array<double, 3> a, std::array<double, 3> b,
                    std::array<double, 3> c) {
  const KnotVector ku({3, {0, 0, 0, 0.5, 1.2, 2, 2, 2}}), kv({3, {0, 0, 0, 0.4, 1, 1, 1}});
  const auto gu = ku.greville(), gv = kv.greville();
  std::vector<double> pts;
  for (double v : gv)
    for (double u : gu) {
      for (int d = 0; d < 3; ++d) pts.push_back(o[d] + u * a[d] + v * b[d]);
      pts.push_back(c[0] + c[1] * u + c[2] * v);
    }
  return Surface({ku, kv}, 4, pts);
}

const std::vector<Pt> outer_polygon{{0.1, 0.1}, {1.9, 0.2}, {1.7, 0.8}, {0.9, 0.95}, {0.2, 0.7}};
const std::vector<Pt> hole_polygon{{0.6, 0.4}, {1.0, 0.3}, {1.3, 0.55}, {0.8, 0.6}};  // made clockwise below

std::vector<Pt> clockwise(std::vector<Pt> p) {
  if (shoelace(p) > 0) std::reverse(p.begin(), p.end());
  return p;
}

double norm3(std::array<double, 3> a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }
std::array<double, 3> cross3(std::array<double, 3> a, std::array<double, 3> b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

/// Where quads of `un` share a side: at per_side - 1 points inside each side of each quad, away
/// (by `off`) from the trimming polylines, the point of every other quad's patch at the same
/// domain point. Every such side point must have a neighbour; returns how many were checked and
/// the largest distance in space.
std::pair<int, double> neighbour_gap(const geom::Untrimmed& un, const std::vector<std::vector<Pt>>& trims,
                                     int per_side, double off) {
  int shared = 0;
  double gap = 0.0;
  for (std::size_t i = 0; i < un.domains.size(); ++i)
    for (int side = 0; side < 4; ++side)
      for (int j = 1; j < per_side; ++j) {
        const double r = double(j) / per_side;
        const std::array<double, 2> st = side == 0 ? std::array<double, 2>{r, 0} : side == 1 ? std::array<double, 2>{1, r}
                                         : side == 2 ? std::array<double, 2>{r, 1} : std::array<double, 2>{0, r};
        const auto q = un.domains[i].eval(st);
        const Pt x{q[0], q[1]};
        bool on_trim = false;
        for (const auto& t : trims) on_trim = on_trim || polyline_distance(t, x) < off;
        if (on_trim) continue;
        const auto p = un.patches[i].eval(st);
        int partners = 0;
        for (std::size_t k = 0; k < un.domains.size(); ++k) {
          std::array<double, 2> st2;
          if (k == i || !invert(un.domains[k], x, st2)) continue;
          const auto p2 = un.patches[k].eval({st2[0], st2[1]});
          for (int d = 0; d < 3; ++d) gap = std::max(gap, std::abs(p[d] - p2[d]));
          ++partners;
        }
        if (partners == 0) std::printf("side point of quad %zu (side %d, at %g) without a neighbour: (%.17g, %.17g)\n", i, side, r, x[0], x[1]);
        CHECK(partners >= 1);
        ++shared;
      }
  return {shared, gap};
}

}  // namespace

TEST_CASE("untrim: a planar face with a polygonal hole", "[trimmed_surface]") {
  const std::array<double, 3> o{1, -2, 0.5}, a{1.5, 0.2, 0.3}, b{-0.4, 0.9, 0.7}, c{2.0, 0.5, -1.5};
  const Surface face = affine_face(o, a, b, c);
  const auto hole = clockwise(hole_polygon);
  REQUIRE(shoelace(outer_polygon) > 0);
  REQUIRE(shoelace(hole) < 0);
  const TrimmedSurface ts(face, {polygon_loop(outer_polygon), polygon_loop(hole)});
  const auto un = geom::untrim(ts);
  const double scale = norm3(cross3(a, b));
  const double expected = scale * (shoelace(outer_polygon) + shoelace(hole));
  const auto mo = moments(outer_polygon), mh = moments(hole);
  const double expected_f = scale * (c[0] * (shoelace(outer_polygon) + shoelace(hole)) + c[1] * (mo[0] + mh[0]) +
                                     c[2] * (mo[1] + mh[1]));
  const double got = geom::area(un), got_f = geom::integrate_coordinate(un, 3);
  std::printf("planar face with hole: %lld patches, area %.15g (expected %.15g), int f %.15g (expected %.15g), "
              "composition error %.3g, largest orders (%d, %d)\n",
              static_cast<long long>(un.report.patches), got, expected, got_f, expected_f,
              un.report.max_composition_error, un.report.max_order_s, un.report.max_order_t);
  CHECK(un.report.exact);
  CHECK(un.report.patches == static_cast<std::int64_t>(un.patches.size()));
  CHECK(un.patches.size() == un.domains.size());
  CHECK(std::abs(got - expected) < 1e-8);
  CHECK(std::abs(got_f - expected_f) < 1e-8);
  CHECK(std::abs(geom::area(ts) - expected) < 1e-8);
  CHECK(un.report.max_composition_error < 1e-12);
  // Every point of every quad lies in the trimmed domain (or on its boundary); its patch point
  // is the affine image.
  int checked = 0;
  for (std::size_t i = 0; i < un.domains.size(); ++i)
    for (int j = 0; j <= 6; ++j)
      for (int k = 0; k <= 6; ++k) {
        const auto q = un.domains[i].eval({j / 6.0, k / 6.0});
        const Pt x{q[0], q[1]};
        const bool on_edge = polyline_distance(outer_polygon, x) < 1e-9 || polyline_distance(hole, x) < 1e-9;
        CHECK((on_edge || (in_polygon(outer_polygon, x) && !in_polygon(hole, x))));
        const auto p = un.patches[i].eval({j / 6.0, k / 6.0});
        for (int d = 0; d < 3; ++d) CHECK(std::abs(p[d] - (o[d] + x[0] * a[d] + x[1] * b[d])) < 1e-12);
        CHECK(std::abs(p[3] - (c[0] + c[1] * x[0] + c[2] * x[1])) < 1e-12);
        ++checked;
      }
  CHECK(checked > 0);
  // Orientation: every quad map's Jacobian determinant is non-negative (the patches keep the
  // orientation of the face).
  for (const auto& q : un.domains)
    for (int j = 0; j <= 4; ++j)
      for (int k = 0; k <= 4; ++k) {
        const auto d = q.eval_derivatives({j / 4.0, k / 4.0}, 1);
        CHECK(d[2] * d[5] - d[4] * d[3] >= -1e-12);
      }
}

TEST_CASE("untrim: random points lie in exactly one quad inside, none outside", "[trimmed_surface]") {
  const Surface face = affine_face({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0});
  const auto hole = clockwise(hole_polygon);
  const auto un = geom::untrim(TrimmedSurface(face, {polygon_loop(outer_polygon), polygon_loop(hole)}));
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> U(0.0, 2.0), V(0.0, 1.0);
  int inside = 0, outside = 0;
  for (int n = 0; n < 1500; ++n) {
    const Pt x{U(rng), V(rng)};
    if (polyline_distance(outer_polygon, x) < 1e-6 || polyline_distance(hole, x) < 1e-6) continue;
    const bool in = in_polygon(outer_polygon, x) && !in_polygon(hole, x);
    int count = 0;
    std::array<double, 2> st;
    for (const auto& q : un.domains) count += invert(q, x, st) ? 1 : 0;
    CHECK(count == (in ? 1 : 0));
    (in ? inside : outside) += 1;
  }
  std::printf("random points: %d inside, %d outside\n", inside, outside);
  CHECK(inside > 300);
  CHECK(outside > 300);
}

TEST_CASE("untrim: neighbouring patches meet along their sides", "[trimmed_surface]") {
  const Surface face = affine_face({0, 0, 0}, {1, 0.3, 0.2}, {0.1, 1, -0.5}, {1, 1, 1});
  const auto hole = clockwise(hole_polygon);
  const auto un = geom::untrim(TrimmedSurface(face, {polygon_loop(outer_polygon), polygon_loop(hole)}));
  const auto [shared, gap] = neighbour_gap(un, {outer_polygon, hole}, 10, 1e-9);
  std::printf("shared side points: %d, largest gap %.3g\n", shared, gap);
  CHECK(shared > 50);
  CHECK(gap < 1e-9);
}

namespace {

/// A bicubic surface on [0, 1]^2 with knot lines at 0.5: x = u, y = v (Greville), a wavy z, and
/// a property coordinate.
Surface bicubic() {
  const KnotVector k({4, {0, 0, 0, 0, 0.5, 1, 1, 1, 1}});
  const auto g = k.greville();
  std::vector<double> pts;
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 5; ++i) {
      pts.push_back(g[static_cast<std::size_t>(i)]);
      pts.push_back(g[static_cast<std::size_t>(j)]);
      pts.push_back(0.4 * std::sin(1.3 * i + 0.4) * std::cos(0.9 * j - 0.2));
      pts.push_back(1.0 + 0.25 * i - 0.1 * j * j);
    }
  return Surface({k, k}, 4, pts);
}

/// A closed clamped cubic B-spline around (cx, cy): n + 1 control points, the last the first.
Curve blob(double cx, double cy, double r, double wob, int n, bool ccw) {
  std::vector<double> pts;
  for (int i = 0; i <= n; ++i) {
    const double th = 2 * M_PI * (i % n) / n * (ccw ? 1 : -1) + 0.3;
    const double rr = r * (1 + wob * std::cos(3 * th));
    pts.push_back(cx + rr * std::cos(th));
    pts.push_back(cy + rr * std::sin(th));
  }
  return Curve({KnotVector::uniform(4, n + 1 - 3)}, 2, pts);
}

/// -(loop integral of F(u, v) du), F(u, v) = int_0^v g(u, w) dw, g = f |S_u x S_v| (f = 1 or
/// coordinate `coord`): the integral of g over the region the loops enclose (Green's theorem).
double green_integral(const Surface& s, const std::vector<Curve>& curves, int coord) {
  const auto rule = geom::gauss_legendre(24);
  auto g = [&](double u, double v) {
    const auto d = s.eval_derivatives({u, v}, 1);
    const int k = s.dim();
    const std::array<double, 3> a{d[static_cast<std::size_t>(k)], d[static_cast<std::size_t>(k) + 1], d[static_cast<std::size_t>(k) + 2]};
    const std::array<double, 3> b{d[static_cast<std::size_t>(2 * k)], d[static_cast<std::size_t>(2 * k) + 1], d[static_cast<std::size_t>(2 * k) + 2]};
    return (coord < 0 ? 1.0 : d[static_cast<std::size_t>(coord)]) * norm3(cross3(a, b));
  };
  auto F = [&](double u, double v) {
    double total = 0.0;
    const double cuts[3] = {0.0, std::min(v, 0.5), v};
    for (int piece = 0; piece < 2; ++piece) {
      const double lo = cuts[piece], hi = cuts[piece + 1];
      if (hi <= lo) continue;
      for (std::size_t i = 0; i < rule.nodes.size(); ++i)
        total += 0.5 * (hi - lo) * rule.weights[i] * g(u, 0.5 * (lo + hi) + 0.5 * (hi - lo) * rule.nodes[i]);
    }
    return total;
  };
  double total = 0.0;
  const auto r16 = geom::gauss_legendre(16);
  for (const auto& c : curves) {
    const auto dom = c.domain(0);
    const int sub = 400;
    for (int e = 0; e < sub; ++e) {
      const double t0 = dom[0] + (dom[1] - dom[0]) * e / sub, t1 = dom[0] + (dom[1] - dom[0]) * (e + 1) / sub;
      for (std::size_t i = 0; i < r16.nodes.size(); ++i) {
        const double t = 0.5 * (t0 + t1) + 0.5 * (t1 - t0) * r16.nodes[i];
        const auto d = c.eval_derivatives({t}, 1);  // u v u' v'
        total -= 0.5 * (t1 - t0) * r16.weights[i] * F(d[0], d[1]) * d[2];
      }
    }
  }
  return total;
}

std::vector<Pt> dense(const Curve& c, int n) {
  std::vector<Pt> p;
  const auto dom = c.domain(0);
  for (int i = 0; i < n; ++i) {
    const auto x = c.eval({dom[0] + (dom[1] - dom[0]) * i / n});
    p.push_back({x[0], x[1]});
  }
  return p;
}

}  // namespace

TEST_CASE("untrim: a bicubic surface trimmed by cubic B-spline loops", "[trimmed_surface]") {
  const Surface s = bicubic();
  const Curve outer = blob(0.48, 0.47, 0.33, 0.12, 9, true);
  const Curve hole = blob(0.56, 0.52, 0.1, 0.05, 7, false);
  // The outer loop in two pieces.
  auto [o1, o2] = spline::split(outer, 0, 0.37);
  const TrimmedSurface ts(s, {TrimLoop{{o1, o2}}, TrimLoop{{hole}}});
  REQUIRE(ts.loop_areas()[0] > 0);
  REQUIRE(ts.loop_areas()[1] < 0);
  const auto un = geom::untrim(ts);
  const double expected = green_integral(s, {outer, hole}, -1);
  const double expected_f = green_integral(s, {outer, hole}, 3);
  const double got = geom::area(un), got_f = geom::integrate_coordinate(un, 3);
  std::printf("bicubic with cubic loops: %lld patches, orders up to (%d, %d), area %.15g (Green %.15g, "
              "difference %.3g), int f %.15g (Green %.15g), composition error %.3g\n",
              static_cast<long long>(un.report.patches), un.report.max_order_s, un.report.max_order_t, got,
              expected, got - expected, got_f, expected_f, un.report.max_composition_error);
  CHECK(std::abs(got - expected) < 1e-7);
  CHECK(std::abs(got_f - expected_f) < 1e-7);
  CHECK(un.report.max_composition_error < 1e-10);
  // Composition: each patch is S(q(s, t)) at random points.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> R(0.0, 1.0);
  double err = 0.0;
  for (std::size_t i = 0; i < un.patches.size(); ++i)
    for (int n = 0; n < 10; ++n) {
      const double a = R(rng), b = R(rng);
      const auto q = un.domains[i].eval({a, b});
      const auto x = s.eval({q[0], q[1]});
      const auto p = un.patches[i].eval({a, b});
      for (std::size_t d = 0; d < x.size(); ++d) err = std::max(err, std::abs(x[d] - p[d]));
    }
  std::printf("bicubic: largest |patch - S(q)| at random points %.3g\n", err);
  CHECK(err < 1e-10);
  // Coverage against the loops' dense polylines.
  const auto po = dense(outer, 4000), ph = dense(hole, 4000);
  int inside = 0, outside = 0;
  std::uniform_real_distribution<double> D(0.0, 1.0);
  for (int n = 0; n < 600; ++n) {
    const Pt x{D(rng), D(rng)};
    if (polyline_distance(po, x) < 1e-5 || polyline_distance(ph, x) < 1e-5) continue;
    const bool in = winding(po, x) + winding(ph, x) == 1;
    int count = 0;
    std::array<double, 2> st;
    for (const auto& q : un.domains) count += invert(q, x, st) ? 1 : 0;
    CHECK(count == (in ? 1 : 0));
    (in ? inside : outside) += 1;
  }
  CHECK(inside > 100);
  CHECK(outside > 100);
  // Neighbours meet in space.
  const auto [shared, gap] = neighbour_gap(un, {po, ph}, 6, 1e-6);
  std::printf("bicubic: shared side points %d, largest gap %.3g\n", shared, gap);
  CHECK(shared > 20);
  CHECK(gap < 1e-9);
  // Deterministic: the same input gives the same patches.
  const auto again = geom::untrim(ts);
  REQUIRE(again.patches.size() == un.patches.size());
  for (std::size_t i = 0; i < un.patches.size(); ++i) CHECK(again.patches[i] == un.patches[i]);
}

TEST_CASE("untrim: a quarter cylinder trimmed by a cubic loop", "[trimmed_surface]") {
  // The cubic Bezier quarter circle (1, 0), (1, k), (k, 1), (0, 1) swept along z in [0, 2]:
  // area element |c'(u)|, so the trimmed area is -(loop integral of |c'(u)| v du).
  const double k = 0.5522847498;
  const Surface cyl({KnotVector::bezier(4), KnotVector::bezier(2, 0.0, 2.0)}, 3,
                    std::vector<double>{1, 0, 0, 1, k, 0, k, 1, 0, 0, 1, 0, 1, 0, 2, 1, k, 2, k, 1, 2, 0, 1, 2});
  const Curve loop = blob(0.5, 1.0, 0.35, 0.1, 8, true);
  const auto un = geom::untrim(TrimmedSurface(cyl, {TrimLoop{{loop}}}));
  double expected = 0.0;
  const auto r = geom::gauss_legendre(16);
  const auto dom = loop.domain(0);
  for (int e = 0; e < 400; ++e) {
    const double t0 = dom[0] + (dom[1] - dom[0]) * e / 400, t1 = dom[0] + (dom[1] - dom[0]) * (e + 1) / 400;
    for (std::size_t i = 0; i < r.nodes.size(); ++i) {
      const auto d = loop.eval_derivatives({0.5 * (t0 + t1) + 0.5 * (t1 - t0) * r.nodes[i]}, 1);
      const auto c = cyl.eval_derivatives({d[0], 0.0}, 1);  // x y z, x_u y_u z_u, x_v y_v z_v
      expected -= 0.5 * (t1 - t0) * r.weights[i] * std::hypot(c[3], c[4]) * d[1] * d[2];
    }
  }
  std::printf("quarter cylinder: %lld patches, area %.15g (Green %.15g)\n", static_cast<long long>(un.report.patches),
              geom::area(un), expected);
  CHECK(std::abs(geom::area(un) - expected) < 1e-9);
  CHECK(un.report.max_composition_error < 1e-12);
}

TEST_CASE("untrim: no loops untrims the whole surface", "[trimmed_surface]") {
  const Surface face = affine_face({0, 0, 0}, {2, 0, 0}, {0, 3, 0}, {0, 0, 0});
  const auto un = geom::untrim(TrimmedSurface(face, {}));
  CHECK(un.patches.size() == 6);  // 3 x 2 Bezier pieces
  // A rectangle between knot lines composes to the biquadratic piece itself.
  CHECK(un.report.max_order_s == 3);
  CHECK(un.report.max_order_t == 3);
  CHECK(std::abs(geom::area(un) - 2.0 * 3.0 * 2.0) < 1e-12);  // [0, 2] x [0, 1] scaled by 2 x 3
}

TEST_CASE("untrim: edges along knot lines and the domain's edge", "[trimmed_surface]") {
  // The face's knot lines are u = 0.5, 1.2 and v = 0.4; this polygon runs along three of them
  // and along the edge u = 2.
  const Surface face = affine_face({0, 0, 0}, {1, 0, 0}, {0, 2, 0}, {0, 0, 0});
  const std::vector<Pt> p{{0.5, 0.1}, {1.2, 0.1}, {1.2, 0.4}, {2.0, 0.4}, {2.0, 0.9}, {0.5, 0.9}};
  const auto un = geom::untrim(TrimmedSurface(face, {polygon_loop(p)}));
  CHECK(std::abs(geom::area(un) - 2.0 * shoelace(p)) < 1e-12);
  for (const auto& q : un.domains)
    for (int j = 0; j <= 4; ++j)
      for (int k = 0; k <= 4; ++k) {
        const auto x = q.eval({j / 4.0, k / 4.0});
        CHECK((in_polygon(p, {x[0], x[1]}) || polyline_distance(p, {x[0], x[1]}) < 1e-12));
      }
}

TEST_CASE("untrim: a crescent whose tips no straight chord separates", "[trimmed_surface]") {
  // Two quadratic arcs bulging the same way meet at (0.2, 0.3) and (1.8, 0.3); their middle
  // control points are off centre, so u is not linear along them. The area enclosed by a loop
  // of quadratic Bezier arcs is sum (2 P0 x P1 + 2 P1 x P2 + P0 x P2) / 6 (Green's theorem).
  const std::vector<std::array<Pt, 3>> arcs{{{{0.2, 0.3}, {0.7, 0.6}, {1.8, 0.3}}}, {{{1.8, 0.3}, {1.3, 1.0}, {0.2, 0.3}}}};
  TrimLoop loop;
  double expected = 0.0;
  auto cr = [](Pt a, Pt b) { return a[0] * b[1] - a[1] * b[0]; };
  for (const auto& a : arcs) {
    loop.pieces.push_back(Curve({KnotVector::bezier(3)}, 2, std::vector<double>{a[0][0], a[0][1], a[1][0], a[1][1], a[2][0], a[2][1]}));
    expected += (2 * cr(a[0], a[1]) + 2 * cr(a[1], a[2]) + cr(a[0], a[2])) / 6.0;
  }
  const Surface face = affine_face({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0});
  const auto un = geom::untrim(TrimmedSurface(face, {loop}));
  std::printf("crescent: %lld patches, area %.15g (expected %.15g)\n", static_cast<long long>(un.report.patches),
              geom::area(un), expected);
  CHECK(std::abs(geom::area(un) - expected) < 1e-12);
  std::vector<Pt> poly;
  for (const auto& c : loop.pieces)
    for (const auto& x : dense(c, 2000)) poly.push_back(x);
  for (const auto& q : un.domains)
    for (int j = 0; j <= 4; ++j)
      for (int k = 0; k <= 4; ++k) {
        const auto x = q.eval({j / 4.0, k / 4.0});
        CHECK((winding(poly, {x[0], x[1]}) == 1 || polyline_distance(poly, {x[0], x[1]}) < 1e-6));
      }
}

TEST_CASE("untrim: refusals", "[trimmed_surface]") {
  const Surface face = affine_face({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0});
  auto message = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  // Open loop: three sides of a square.
  TrimLoop open = polygon_loop({{0.2, 0.2}, {0.8, 0.2}, {0.8, 0.8}, {0.2, 0.8}});
  open.pieces.pop_back();
  const auto m1 = message([&] { TrimmedSurface(face, {open}); });
  CHECK_THAT(m1, Catch::Contains("trimming loop 0, piece 2") && Catch::Contains("closed loop"));
  // Outside the rectangle [0, 2] x [0, 1].
  const auto m2 = message([&] { TrimmedSurface(face, {polygon_loop({{0.2, 0.2}, {2.3, 0.2}, {0.2, 0.8}})}); });
  CHECK_THAT(m2, Catch::Contains("trimming loop 0, piece 0") && Catch::Contains("outside the parameter rectangle"));
  // A curved piece whose control polygon leaves the rectangle while the curve stays inside is
  // accepted; one whose curve leaves it is refused.
  {
    const Curve arc({KnotVector::bezier(3)}, 2, std::vector<double>{1.8, 0.5, 1.0, 1.1, 0.2, 0.5});  // top at v = 0.8
    CHECK_NOTHROW(TrimmedSurface(face, {TrimLoop{{arc, line({0.2, 0.5}, {1.8, 0.5})}}}));
    const Curve high({KnotVector::bezier(3)}, 2, std::vector<double>{1.8, 0.5, 1.0, 1.7, 0.2, 0.5});  // top 1.1
    CHECK_THAT(message([&] { TrimmedSurface(face, {TrimLoop{{high, line({0.2, 0.5}, {1.8, 0.5})}}}); }),
               Catch::Contains("outside the parameter rectangle"));
  }
  // A bow tie crosses itself.
  CHECK_THAT(message([&] { TrimmedSurface(face, {polygon_loop({{0.2, 0.2}, {0.8, 0.8}, {0.8, 0.2}, {0.2, 0.8}})}); }),
             Catch::Contains("meets"));
  // Two crossing squares.
  CHECK_THAT(message([&] {
               TrimmedSurface(face, {polygon_loop({{0.2, 0.2}, {0.8, 0.2}, {0.8, 0.8}, {0.2, 0.8}}),
                                     polygon_loop({{0.5, 0.5}, {1.5, 0.5}, {1.5, 0.9}, {0.5, 0.9}})});
             }),
             Catch::Contains("trimming loop 0") && Catch::Contains("trimming loop 1"));
  // Clockwise only.
  CHECK_THAT(message([&] { TrimmedSurface(face, {polygon_loop({{0.2, 0.2}, {0.2, 0.8}, {0.8, 0.8}, {0.8, 0.2}})}); }),
             Catch::Contains("counter-clockwise"));
  // Two nested counter-clockwise loops: winding number 2 inside the inner one.
  const TrimmedSurface nested(face, {polygon_loop({{0.1, 0.1}, {1.9, 0.1}, {1.9, 0.9}, {0.1, 0.9}}),
                                     polygon_loop({{0.5, 0.3}, {1.0, 0.3}, {1.0, 0.6}, {0.5, 0.6}})});
  CHECK_THAT(message([&] { geom::untrim(nested); }), Catch::Contains("winding number 2"));
  // A hole outside every outer loop: winding number -1.
  const TrimmedSurface stray(face, {polygon_loop({{0.1, 0.1}, {0.9, 0.1}, {0.9, 0.9}, {0.1, 0.9}}),
                                    polygon_loop({{1.2, 0.3}, {1.2, 0.6}, {1.6, 0.6}, {1.6, 0.3}})});
  CHECK_THAT(message([&] { geom::untrim(stray); }), Catch::Contains("winding number -1") && Catch::Contains("trimming loop 1"));
  // A curve of order 33 (over max_order 32).
  {
    std::vector<double> pts;
    for (int i = 0; i < 33; ++i) pts.push_back(0.2 + 0.6 * i / 32.0), pts.push_back(0.2 + 0.3 * std::sin(M_PI * i / 32.0));
    const Curve big({KnotVector::bezier(33)}, 2, pts);
    CHECK_THAT(message([&] { TrimmedSurface(face, {TrimLoop{{big, line({0.8, 0.2}, {0.2, 0.2})}}}); }),
               Catch::Contains("trimming loop 0, piece 0") && Catch::Contains("max_order"));
  }
  // Patches over a lowered max_order: a bicubic surface and a cubic loop give orders (19, 4).
  {
    const TrimmedSurface ts(bicubic(), {TrimLoop{{blob(0.5, 0.5, 0.3, 0.1, 8, true)}}});
    geom::UntrimOptions small;
    small.limits.max_order = 12;
    CHECK_THAT(message([&] { geom::untrim(ts, small); }), Catch::Contains("max_order") && Catch::Contains("(19, 4)"));
    geom::UntrimOptions few;
    few.max_patches = 3;
    CHECK_THAT(message([&] { geom::untrim(ts, few); }), Catch::Contains("max_patches"));
  }
  // A rational surface.
  {
    Surface r = face;
    r.weights().assign(static_cast<std::size_t>(r.size()), 1.0);
    r.weights()[3] = 2.0;
    CHECK_THAT(message([&] { TrimmedSurface(r, {}); }), Catch::Contains("rational"));
  }
}
