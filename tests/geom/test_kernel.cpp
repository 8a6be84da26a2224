// Conservative kernels (geom/kernel.hpp). Truths: the kernel of a convex polygon is the polygon
// (shoelace area and centroid); an L-shaped hexagon's kernel is the unit square at its corner; a
// U-shape and a slit annulus see no common point; for curved loops the kernel lies inside the
// true kernel (every sampled tangent line keeps its vertices on the inner side), grows with
// refinement and approaches the kernel cut by densely sampled tangent lines; a box's kernel is
// the box (volume), whatever the orientation of its parametrisation.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include "trivox/error.hpp"
#include "trivox/geom/kernel.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/refine.hpp"

using namespace trivox;
using spline::Curve;
using spline::KnotVector;
using spline::Surface;
using spline::Trivariate;
using Pt = std::array<double, 2>;

namespace {

Curve bezier_curve(const std::vector<Pt>& pts) {
  std::vector<double> c;
  for (const Pt& p : pts) c.insert(c.end(), p.begin(), p.end());
  return Curve({KnotVector::bezier(static_cast<int>(pts.size()))}, 2, c);
}

std::vector<Curve> polygon(const std::vector<Pt>& v) {
  std::vector<Curve> loop;
  for (std::size_t i = 0; i < v.size(); ++i) loop.push_back(bezier_curve({v[i], v[(i + 1) % v.size()]}));
  return loop;
}

double shoelace(const std::vector<Pt>& v) {
  double a = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Pt& p = v[i];
    const Pt& q = v[(i + 1) % v.size()];
    a += p[0] * q[1] - q[0] * p[1];
  }
  return 0.5 * a;
}

Pt polygon_centroid(const std::vector<Pt>& v) {
  double a = 0.0, cx = 0.0, cy = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Pt& p = v[i];
    const Pt& q = v[(i + 1) % v.size()];
    const double w = p[0] * q[1] - q[0] * p[1];
    a += w, cx += w * (p[0] + q[0]), cy += w * (p[1] + q[1]);
  }
  return {cx / (3 * a), cy / (3 * a)};
}

/// min over sampled t of the CCW-normalised C'(t) x (K - C(t)) / |C'(t)|, over the loop.
double worst_tangent_side(const std::vector<Curve>& loop, const Pt& k, int orientation, int samples = 400) {
  double worst = HUGE_VAL;
  for (const Curve& c : loop)
    for (int s = 0; s <= samples; ++s) {
      const double t = c.domain(0)[0] + (c.domain(0)[1] - c.domain(0)[0]) * s / samples;
      const auto d = c.eval_derivatives({t}, 1);  // x, y, x', y'
      const double len = std::hypot(d[2], d[3]);
      if (len == 0.0) continue;
      worst = std::min(worst, orientation * (d[2] * (k[1] - d[1]) - d[3] * (k[0] - d[0])) / len);
    }
  return worst;
}

/// The kernel cut by the sampled tangent lines alone (a superset of the true kernel), by clipping
/// a big square: an independent estimate of the true kernel's area.
double sampled_kernel_area(const std::vector<Curve>& loop, int samples) {
  std::vector<Pt> poly{{-100, -100}, {100, -100}, {100, 100}, {-100, 100}};
  for (const Curve& c : loop)
    for (int s = 0; s <= samples; ++s) {
      const double t = c.domain(0)[0] + (c.domain(0)[1] - c.domain(0)[0]) * s / samples;
      const auto d = c.eval_derivatives({t}, 1);
      auto side = [&](const Pt& p) { return d[2] * (p[1] - d[1]) - d[3] * (p[0] - d[0]); };
      std::vector<Pt> out;
      for (std::size_t i = 0; i < poly.size(); ++i) {
        const Pt& p = poly[i];
        const Pt& q = poly[(i + 1) % poly.size()];
        const double a = side(p), b = side(q);
        if (a >= 0) out.push_back(p);
        if ((a > 0 && b < 0) || (a < 0 && b > 0)) {
          const double f = a / (a - b);
          out.push_back({p[0] + f * (q[0] - p[0]), p[1] + f * (q[1] - p[1])});
        }
      }
      poly = out;
      if (poly.size() < 3) return 0.0;
    }
  return shoelace(poly);
}

/// A loop with an S-shaped (inflected) cubic bottom and three straight sides.
std::vector<Curve> wavy_square() {
  return {bezier_curve({{0, 0}, {1, 0.9}, {2, -0.9}, {3, 0}}), bezier_curve({{3, 0}, {3, 3}}),
          bezier_curve({{3, 3}, {0, 3}}), bezier_curve({{0, 3}, {0, 0}})};
}

/// Quarter-circle cubic Bezier arcs of radius r from angle a0 by +-90 degrees (sign of `turn`).
Curve arc(double r, double a0, double turn) {
  const double k = 0.5522847498307936 * (turn > 0 ? 1 : -1);
  const double a1 = a0 + turn;
  const Pt p0{r * std::cos(a0), r * std::sin(a0)}, p3{r * std::cos(a1), r * std::sin(a1)};
  const Pt p1{p0[0] - k * r * std::sin(a0), p0[1] + k * r * std::cos(a0)};
  const Pt p2{p3[0] + k * r * std::sin(a1), p3[1] - k * r * std::cos(a1)};
  return bezier_curve({p0, p1, p2, p3});
}

Trivariate box(const std::array<double, 3>& lo, const std::array<double, 3>& hi) {
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) pts.insert(pts.end(), {i ? hi[0] : lo[0], j ? hi[1] : lo[1], k ? hi[2] : lo[2]});
  return Trivariate({KnotVector::bezier(2), KnotVector::bezier(2), KnotVector::bezier(2)}, 3, pts);
}

}  // namespace

TEST_CASE("the kernel of a convex polygon is the polygon itself", "[kernel]") {
  const std::vector<Pt> v{{0, 0}, {4, -1}, {5, 2}, {2, 4}, {-1, 2}};
  for (int refinements : {0, 2}) {
    const auto k = geom::planar_kernel(polygon(v), {refinements});
    REQUIRE_FALSE(k.empty());
    CHECK(k.orientation == 1);
    CHECK(k.area == Approx(shoelace(v)).epsilon(1e-12));
    const Pt c = polygon_centroid(v);
    CHECK(k.centroid[0] == Approx(c[0]).epsilon(1e-12));
    CHECK(k.centroid[1] == Approx(c[1]).epsilon(1e-12));
    CHECK(k.vertices.size() == v.size());
  }
  SECTION("traversed clockwise: the same kernel, orientation -1") {
    std::vector<Pt> w(v.rbegin(), v.rend());
    const auto k = geom::planar_kernel(polygon(w));
    CHECK(k.orientation == -1);
    CHECK(k.area == Approx(shoelace(v)).epsilon(1e-12));
  }
}

TEST_CASE("an L-shaped hexagon has the unit square at its corner as kernel", "[kernel]") {
  const std::vector<Pt> v{{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  const auto k = geom::planar_kernel(polygon(v));
  REQUIRE_FALSE(k.empty());
  CHECK(k.area == Approx(1.0).epsilon(1e-12));
  CHECK(k.centroid[0] == Approx(0.5).epsilon(1e-12));
  CHECK(k.centroid[1] == Approx(0.5).epsilon(1e-12));
  for (const Pt& p : k.vertices) {
    CHECK(p[0] >= -1e-12);
    CHECK(p[0] <= 1 + 1e-12);
    CHECK(p[1] >= -1e-12);
    CHECK(p[1] <= 1 + 1e-12);
  }
}

TEST_CASE("loops that are not star-shaped have no kernel", "[kernel]") {
  SECTION("a U") {
    const std::vector<Pt> v{{0, 0}, {3, 0}, {3, 3}, {2, 3}, {2, 1}, {1, 1}, {1, 3}, {0, 3}};
    CHECK(geom::planar_kernel(polygon(v)).empty());
  }
  SECTION("a slit annulus of cubic arcs (outer radius 2, inner 1, three quarters round)") {
    const double q = M_PI / 2;
    std::vector<Curve> loop{arc(2, 0, q), arc(2, q, q), arc(2, 2 * q, q)};
    loop.push_back(bezier_curve({{0, -2}, {0, -1}}));
    loop.push_back(arc(1, 3 * q, -q));
    loop.push_back(arc(1, 2 * q, -q));
    loop.push_back(arc(1, q, -q));
    loop.push_back(bezier_curve({{1, 0}, {2, 0}}));
    for (int r : {0, 4}) CHECK(geom::planar_kernel(loop, {r}).empty());
  }
}

TEST_CASE("the conservative kernel of a curved loop lies in the true kernel and grows with refinement",
          "[kernel]") {
  const auto loop = wavy_square();
  const double estimate = sampled_kernel_area(loop, 4000);
  REQUIRE(estimate > 1.0);
  double previous = 0.0;
  for (int r = 0; r <= 5; ++r) {
    const auto k = geom::planar_kernel(loop, {r});
    REQUIRE_FALSE(k.empty());
    INFO("refinements " << r << ", area " << k.area << ", sampled " << estimate);
    CHECK(k.area >= previous * (1 - 1e-12));
    CHECK(k.area <= estimate * (1 + 1e-9));
    for (const Pt& p : k.vertices) CHECK(worst_tangent_side(loop, p, 1) >= -1e-9);
    CHECK(worst_tangent_side(loop, k.centroid, 1) > 0.0);
    previous = k.area;
  }
  // Five halvings: within a few percent of the tangent-line estimate.
  CHECK(previous >= 0.95 * estimate);
}

TEST_CASE("the kernel of a planar surface's boundary", "[kernel]") {
  // The bilinear surface on the quadrilateral (0,0) (3,0) (4,2) (-1,3): kernel = quadrilateral.
  const std::vector<Pt> quad{{0, 0}, {3, 0}, {4, 2}, {-1, 3}};
  Surface s({KnotVector::bezier(2), KnotVector::bezier(2)}, 2, {0, 0, 3, 0, -1, 3, 4, 2});
  const auto k = geom::planar_kernel(s);
  CHECK(k.orientation == 1);
  CHECK(k.area == Approx(shoelace(quad)).epsilon(1e-12));
  const auto loop = geom::boundary_loop(s);
  REQUIRE(loop.size() == 4);
  CHECK(loop[2].eval({0.0})[0] == Approx(4.0));  // S(u, 1) reversed starts at S(1, 1)
  SECTION("u and v swapped: det J < 0, the same kernel with orientation -1") {
    const auto ks = geom::planar_kernel(spline::swap_directions(spline::elevate(s, 0, 2), 0, 1));
    CHECK(ks.orientation == -1);
    CHECK(ks.area == Approx(shoelace(quad)).epsilon(1e-10));
  }
}

TEST_CASE("a loop with a gap names the two curves", "[kernel]") {
  auto loop = polygon({{0, 0}, {1, 0}, {1, 1}});
  loop[1] = bezier_curve({{1.5, 0}, {1, 1}});
  try {
    geom::planar_kernel(loop);
    FAIL("no error");
  } catch (const Error& e) {
    const std::string m = e.what();
    CHECK(m.find("curve 0") != std::string::npos);
    CHECK(m.find("curve 1") != std::string::npos);
    CHECK(m.find("0.5") != std::string::npos);
    CHECK(e.kind() == ErrorKind::bad_input);
  }
  CHECK_THROWS_AS(geom::planar_kernel(polygon({{0, 0}, {1, 1}})), Error);  // zero area
}

TEST_CASE("the kernel of a box's six faces is the box", "[kernel]") {
  const Trivariate t = box({0, 0, 0}, {2, 3, 4});
  for (const Trivariate& c : {t, spline::reverse(t, 2), spline::elevate(spline::elevate(t, 0, 2), 2, 1)}) {
    const auto k = geom::spatial_kernel(c);
    REQUIRE_FALSE(k.empty());
    CHECK(k.volume == Approx(24.0).epsilon(1e-10));
    CHECK(k.centroid[0] == Approx(1.0).epsilon(1e-10));
    CHECK(k.centroid[1] == Approx(1.5).epsilon(1e-10));
    CHECK(k.centroid[2] == Approx(2.0).epsilon(1e-10));
    CHECK(k.vertices.size() == 8);
    CHECK(k.faces.size() == 6);
  }
  CHECK(geom::spatial_kernel(t).orientation == 1);
  CHECK(geom::spatial_kernel(spline::reverse(t, 2)).orientation == -1);  // det J < 0: inward normals
  // Faces given with inward normals: found from the signed volume.
  auto faces = geom::oriented_boundary(t);
  for (auto& f : faces) f = spline::reverse(f, 1);
  const auto k = geom::spatial_kernel(faces);
  CHECK(k.orientation == -1);
  CHECK(k.volume == Approx(24.0).epsilon(1e-10));
}

TEST_CASE("a box with a dented top: the kernel lies below every tangent plane and grows", "[kernel]") {
  // Bicubic in u and v, linear in w: the top face's four inner control points pushed down.
  Trivariate t = spline::elevate(spline::elevate(box({0, 0, 0}, {3, 3, 3}), 0, 2), 1, 2);
  for (int j = 1; j <= 2; ++j)
    for (int i = 1; i <= 2; ++i) t.point(t.row({i, j, 1}))[2] = 1.5;
  double previous = 0.0;
  for (int r = 0; r <= 3; ++r) {
    const auto k = geom::spatial_kernel(t, {r});
    REQUIRE_FALSE(k.empty());
    CHECK(k.volume < 27.0);
    CHECK(k.volume >= previous * (1 - 1e-12));
    previous = k.volume;
    // Every vertex below (n . (K - S) <= 0 for) the top face's sampled tangent planes.
    const Surface top = spline::boundary_face(t, spline::Face::w1);
    double worst = -HUGE_VAL;
    for (const auto& v : k.vertices)
      for (int a = 0; a <= 20; ++a)
        for (int b = 0; b <= 20; ++b) {
          const auto d = top.eval_derivatives({a / 20.0, b / 20.0}, 1);  // S, S_u, S_v
          const double nx = d[4] * d[8] - d[5] * d[7], ny = d[5] * d[6] - d[3] * d[8], nz = d[3] * d[7] - d[4] * d[6];
          worst = std::max(worst, nx * (v[0] - d[0]) + ny * (v[1] - d[1]) + nz * (v[2] - d[2]));
        }
    CHECK(worst <= 1e-9);
  }
  CHECK(previous > 1.0);
}

TEST_CASE("a degenerate face contributes no constraint: a triangular prism", "[kernel]") {
  // Face u0 collapses to the z axis; the cell is the prism over the triangle (0,0) (1,0) (1,1),
  // height 2: kernel = the prism, volume 1, centroid (2/3, 1/3, 1).
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) pts.insert(pts.end(), {double(i), double(i * j), 2.0 * k});
  const Trivariate t({KnotVector::bezier(2), KnotVector::bezier(2), KnotVector::bezier(2)}, 3, pts);
  const auto k = geom::spatial_kernel(t);
  REQUIRE_FALSE(k.empty());
  CHECK(k.volume == Approx(1.0).epsilon(1e-10));
  CHECK(k.centroid[0] == Approx(2.0 / 3).epsilon(1e-10));
  CHECK(k.centroid[1] == Approx(1.0 / 3).epsilon(1e-10));
  CHECK(k.centroid[2] == Approx(1.0).epsilon(1e-10));
}

TEST_CASE("restrict_kernel cuts a kernel by further half-planes (half-spaces)", "[kernel]") {
  // The unit square's kernel cut by x + y >= 1: the triangle (1,0) (1,1) (0,1).
  const auto square = geom::planar_kernel(polygon({{0, 0}, {1, 0}, {1, 1}, {0, 1}}));
  const std::vector<std::array<double, 3>> cut{{1.0, 1.0, -1.0}};
  const auto tri = geom::restrict_kernel(square, cut);
  REQUIRE_FALSE(tri.empty());
  CHECK(tri.area == Approx(0.5).epsilon(1e-12));
  CHECK(tri.centroid[0] == Approx(2.0 / 3).epsilon(1e-12));
  CHECK(tri.centroid[1] == Approx(2.0 / 3).epsilon(1e-12));
  CHECK(tri.orientation == square.orientation);
  // A constraint without a direction keeps everything (c >= 0) or nothing (c < 0).
  const std::vector<std::array<double, 3>> keep{{0.0, 0.0, 1.0}}, none{{0.0, 0.0, -1.0}};
  CHECK(geom::restrict_kernel(square, keep).area == Approx(1.0).epsilon(1e-12));
  CHECK(geom::restrict_kernel(square, none).empty());
  // Cut away entirely: x >= 2.
  const std::vector<std::array<double, 3>> away{{1.0, 0.0, -2.0}};
  CHECK(geom::restrict_kernel(square, away).empty());

  // The box [0,2] x [0,3] x [0,4] cut by x >= 1 and z <= 1: [1,2] x [0,3] x [0,1].
  const auto k = geom::spatial_kernel(box({0, 0, 0}, {2, 3, 4}));
  const std::vector<std::array<double, 4>> cuts{{1.0, 0.0, 0.0, -1.0}, {0.0, 0.0, -1.0, 1.0}};
  const auto r = geom::restrict_kernel(k, cuts);
  REQUIRE_FALSE(r.empty());
  CHECK(r.volume == Approx(3.0).epsilon(1e-10));
  CHECK(r.centroid[0] == Approx(1.5).epsilon(1e-10));
  CHECK(r.centroid[1] == Approx(1.5).epsilon(1e-10));
  CHECK(r.centroid[2] == Approx(0.5).epsilon(1e-10));
  CHECK(r.vertices.size() == 8);
  CHECK(r.faces.size() == 6);
  const std::vector<std::array<double, 4>> outside{{1.0, 0.0, 0.0, -3.0}};
  CHECK(geom::restrict_kernel(k, outside).empty());
}
