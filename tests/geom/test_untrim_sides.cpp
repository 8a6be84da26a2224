// Untrimming by monotone sides (geom/trimmed_surface.hpp): a trimming curve of many Bezier pieces
// (as a marched intersection curve is) is one side of the quads it bounds between its events.
// Truths:
// - a closed cubic B-spline whose control points lie on a circle, turned by 0.3 rad so that no two
//   of its knots share an abscissa, has a u-monotone run between its two vertical tangents, with
//   the start of the curve (a corner: the clamped curve starts and ends at one control point) the
//   only other event: a square face with it as a hole is tiled by a number of quads set by these
//   few events (at most 16 here), whatever the number of the curve's pieces (240), and no quad is
//   narrower in u than the distance from an event to the next one (1e-3 of the square here),
//   where a cut at every piece end gives hundreds of quads, down to slivers of 1e-9;
// - the patches' area is the square's less the area the curve encloses, 1/2 loop integral of
//   (u v' - v u'), by Gauss quadrature exact for its polynomial integrand on each knot span, and
//   a linear property integrates to the first moments (loop integrals of u^2 v' / 2 and -v^2 u' / 2);
// - the quads tile the domain: a random point inside lies in exactly one quad (Newton inversion of
//   the quad maps), a point in the hole in none; every quad map keeps the orientation
//   (non-negative Jacobian determinant) and its sides s = 0 and s = 1 are vertical segments;
// - a wavy loop (radius 0.4 (1 + 0.3 cos (3 theta + 0.7))) has four vertical tangents, at
//   distinct abscissae (-0.41, -0.29, -0.27, 0.51), and still gives a few quads.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "trivox/geom/quadrature.hpp"
#include "trivox/geom/trimmed_surface.hpp"

using namespace trivox;
using geom::TrimLoop;
using geom::TrimmedSurface;
using spline::Curve;
using spline::KnotVector;
using spline::Surface;

namespace {

using Pt = std::array<double, 2>;

/// The planar face x = u, y = v, z = 0 on [-1, 1]^2, bilinear, with the property f = 1 + 2u - v.
Surface square() {
  std::vector<double> pts;
  for (double v : {-1.0, 1.0})
    for (double u : {-1.0, 1.0}) pts.insert(pts.end(), {u, v, 0.0, 1.0 + 2.0 * u - v});
  return Surface({KnotVector::bezier(2, -1, 1), KnotVector::bezier(2, -1, 1)}, 4, pts);
}

Curve line(Pt a, Pt b) { return Curve({KnotVector::bezier(2)}, 2, std::vector<double>{a[0], a[1], b[0], b[1]}); }

TrimLoop square_loop() {
  const std::vector<Pt> p{{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  TrimLoop l;
  for (std::size_t i = 0; i < p.size(); ++i) l.pieces.push_back(line(p[i], p[(i + 1) % p.size()]));
  return l;
}

/// A closed clamped cubic B-spline, clockwise, with n + 1 control points (the last the first)
/// at radius r (1 + wob cos (3 theta + 0.7)) about the origin, theta from 0.3 (the phase turns
/// the lobes' mirror lines off the u axis, so that no two vertical tangents share an abscissa).
Curve hole(double r, double wob, int n) {
  std::vector<double> pts;
  for (int i = 0; i <= n; ++i) {
    const double th = -2 * M_PI * (i % n) / n + 0.3;
    const double rr = r * (1 + wob * std::cos(3 * th + 0.7));
    pts.push_back(rr * std::cos(th));
    pts.push_back(rr * std::sin(th));
  }
  return Curve({KnotVector::uniform(4, n + 1 - 3)}, 2, pts);
}

/// Loop integrals of the curve: {1/2 (u v' - v u'), u^2 v' / 2, -v^2 u' / 2} (signed area and
/// first moments by Green's theorem), with 4 Gauss points per knot span (exact to degree 7).
std::array<double, 3> green(const Curve& c) {
  const auto rule = geom::gauss_legendre(4);
  std::array<double, 3> g{};
  const auto& k = c.knots(0).knots();
  for (std::size_t i = 0; i + 1 < k.size(); ++i) {
    if (!(k[i + 1] > k[i])) continue;
    for (std::size_t q = 0; q < rule.nodes.size(); ++q) {
      const double h = 0.5 * (k[i + 1] - k[i]), t = 0.5 * (k[i] + k[i + 1]) + h * rule.nodes[q];
      const auto d = c.eval_derivatives({t}, 1);  // u v u' v'
      const double w = h * rule.weights[q];
      g[0] += w * 0.5 * (d[0] * d[3] - d[1] * d[2]);
      g[1] += w * 0.5 * d[0] * d[0] * d[3];
      g[2] -= w * 0.5 * d[1] * d[1] * d[2];
    }
  }
  return g;
}

/// (s, t) with q(s, t) = x by Newton from a 5 x 5 set of starts; false when none converges.
bool invert(const Surface& q, Pt x) {
  for (int a = 0; a < 5; ++a)
    for (int b = 0; b < 5; ++b) {
      double s = 0.1 + 0.2 * a, t = 0.1 + 0.2 * b;
      for (int it = 0; it < 60; ++it) {
        const auto d = q.eval_derivatives({s, t}, 1);
        const double fx = d[0] - x[0], fy = d[1] - x[1];
        if (std::hypot(fx, fy) < 1e-14) break;
        const double det = d[2] * d[5] - d[4] * d[3];
        if (det == 0.0) break;
        s = std::clamp(s - (fx * d[5] - fy * d[4]) / det, 0.0, 1.0);
        t = std::clamp(t - (d[2] * fy - d[3] * fx) / det, 0.0, 1.0);
      }
      const auto v = q.eval({s, t});
      if (std::hypot(v[0] - x[0], v[1] - x[1]) < 1e-11) return true;
    }
  return false;
}

/// The winding number of the closed polyline p about x.
int winding(const std::vector<Pt>& p, Pt x) {
  int w = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Pt a = p[i], b = p[(i + 1) % p.size()];
    const double c = (b[0] - a[0]) * (x[1] - a[1]) - (x[0] - a[0]) * (b[1] - a[1]);
    if (a[1] <= x[1] && b[1] > x[1] && c > 0) ++w;
    if (a[1] > x[1] && b[1] <= x[1] && c < 0) --w;
  }
  return w;
}

struct Widths {
  double narrowest = 1e300;
  bool vertical = true;
  bool oriented = true;
};

Widths quad_widths(const geom::Untrimmed& un) {
  Widths w;
  for (const auto& q : un.domains) {
    for (int j = 0; j <= 4; ++j) {
      const auto a = q.eval({0.0, j / 4.0}), b = q.eval({0.0, 0.0}), c = q.eval({1.0, j / 4.0}), d = q.eval({1.0, 0.0});
      w.vertical = w.vertical && std::abs(a[0] - b[0]) < 1e-12 && std::abs(c[0] - d[0]) < 1e-12;
      for (int k = 0; k <= 8; ++k) {
        const auto g = q.eval_derivatives({k / 8.0, j / 4.0}, 1);
        w.oriented = w.oriented && g[2] * g[5] - g[4] * g[3] >= -1e-12;
      }
    }
    w.narrowest = std::min(w.narrowest, q.eval({1.0, 0.0})[0] - q.eval({0.0, 0.0})[0]);
  }
  return w;
}

}  // namespace

TEST_CASE("untrim: a hole of many cubic pieces is cut at its events only", "[trimmed_surface][untrim_sides]") {
  const Curve c = hole(0.5, 0.0, 240);
  const auto g = green(c);
  REQUIRE(g[0] < 0);  // clockwise
  const TrimmedSurface ts(square(), {square_loop(), TrimLoop{{c}}});
  const auto un = geom::untrim(ts);
  const double area = geom::area(un), f = geom::integrate_coordinate(un, 3);
  // f = 1 + 2u - v over the square less the hole: 4 + (2 M_u - M_v) of the hole, signed.
  const double expected = 4 + g[0], expected_f = 4 + g[0] + 2 * g[1] - g[2];
  const auto w = quad_widths(un);
  std::printf("hole of 240 cubic pieces: %lld patches of %lld Bezier pieces (at most %d in one), narrowest quad %.3g, "
              "area %.15g (Green %.15g), int f %.15g (Green %.15g), composition error %.3g\n",
              static_cast<long long>(un.report.patches), static_cast<long long>(un.report.spans), un.report.max_spans,
              w.narrowest, area, expected, f, expected_f, un.report.max_composition_error);
  CHECK(un.report.patches <= 16);
  CHECK(un.report.spans >= 240);
  CHECK(w.narrowest > 1e-3);
  CHECK(w.vertical);
  CHECK(w.oriented);
  CHECK(std::abs(area - expected) < 1e-12);
  CHECK(std::abs(f - expected_f) < 1e-11);
  CHECK(un.report.max_composition_error < 1e-13);
  // Random points: one quad inside, none in the hole.
  std::vector<Pt> poly;
  for (int i = 0; i < 4800; ++i) {
    const auto x = c.eval({c.domain(0)[0] + (c.domain(0)[1] - c.domain(0)[0]) * i / 4800});
    poly.push_back({x[0], x[1]});
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  int inside = 0, in_hole = 0;
  for (int n = 0; n < 600; ++n) {
    const Pt x{U(rng), U(rng)};
    const double rho = std::hypot(x[0], x[1]);
    if (std::abs(rho - 0.5) < 0.01) continue;  // near the loop (the spline lies within 1e-3 of the circle)
    const bool in = winding(poly, x) == 0;
    int count = 0;
    for (const auto& q : un.domains) count += invert(q, x) ? 1 : 0;
    CHECK(count == (in ? 1 : 0));
    (in ? inside : in_hole) += 1;
  }
  CHECK(inside > 300);
  CHECK(in_hole > 50);
}

TEST_CASE("untrim: a wavy hole gives a few quads per vertical tangent", "[trimmed_surface][untrim_sides]") {
  const Curve c = hole(0.4, 0.3, 300);
  const auto g = green(c);
  const auto un = geom::untrim(TrimmedSurface(square(), {square_loop(), TrimLoop{{c}}}));
  const auto w = quad_widths(un);
  std::printf("wavy hole of 300 cubic pieces: %lld patches, narrowest quad %.3g, area %.15g (Green %.15g)\n",
              static_cast<long long>(un.report.patches), w.narrowest, geom::area(un), 4 + g[0]);
  CHECK(un.report.patches <= 40);
  CHECK(w.narrowest > 1e-3);
  CHECK(w.vertical);
  CHECK(w.oriented);
  CHECK(std::abs(geom::area(un) - (4 + g[0])) < 1e-12);
}
