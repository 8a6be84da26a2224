// Kernel-based constructors (construct/kernel_construct.hpp, Fadila et al. 2023, Alg. 1). Truths,
// checked independently of the code under test: det J from first partials on dense grids (its sign
// shows the regular construction invalid and the kernel-based one valid), the boundaries equal
// the inputs (Fadila et al. 2023 Lemmas 1-3, kept because only interior control points move), the
// interior control points sit at the kernel centroid, properties stay as the regular
// construction made them, and a box's kernel centroid is the box's centre.
#include <catch2/catch.hpp>

#include <cmath>

#include "trivox/construct/kernel_construct.hpp"
#include "trivox/error.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/refine.hpp"

using namespace trivox;
using construct::AddDof;
using construct::KernelOp;
using spline::Curve;
using spline::KnotVector;
using spline::Surface;
using spline::Trivariate;
using Pt = std::array<double, 2>;

namespace {

/// A cubic Bezier curve in R^3: x, y and a property equal to x + 2y at the control points.
Curve cubic(const std::vector<Pt>& p) {
  std::vector<double> c;
  for (const Pt& q : p) c.insert(c.end(), {q[0], q[1], q[0] + 2 * q[1]});
  return Curve({KnotVector::bezier(static_cast<int>(p.size()))}, 3, c);
}

double det2(const Surface& s, double u, double v) {
  const auto d = s.eval_derivatives({u, v}, 1);  // value, d/du, d/dv; dim coordinates each
  const int k = s.dim();
  return d[static_cast<std::size_t>(k)] * d[static_cast<std::size_t>(2 * k + 1)] -
         d[static_cast<std::size_t>(k + 1)] * d[static_cast<std::size_t>(2 * k)];
}

double det3(const Trivariate& s, const std::array<double, 3>& t) {
  const auto v = s.eval_derivatives(t, 1);
  const double* a = v.data() + 3;
  const double* b = v.data() + 6;
  const double* c = v.data() + 9;
  return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
}

/// min and max of det J on an (n+1)^2 grid.
std::array<double, 2> det_range(const Surface& s, int n = 200) {
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double d = det2(s, static_cast<double>(i) / n, static_cast<double>(j) / n);
      lo = std::min(lo, d), hi = std::max(hi, d);
    }
  return {lo, hi};
}

/// Largest distance (all coordinates) between a surface's iso-curve and a curve, sampled.
double boundary_gap(const Surface& s, int dir, double at, const Curve& c) {
  double gap = 0.0;
  for (int i = 0; i <= 100; ++i) {
    const double t = i / 100.0;
    const auto p = s.eval(dir == 1 ? std::array<double, 2>{t, at} : std::array<double, 2>{at, t});
    const auto q = c.eval({t});
    for (std::size_t h = 0; h < q.size(); ++h) gap = std::max(gap, std::abs(p[h] - q[h]));
  }
  return gap;
}

/// Boolean sum inputs [bottom, top, left, right] from the Fadila et al. 2023, Sec. 5.1 generator
/// (inner control points rounded): the Coons patch folds, the boundary is star-shaped.
std::vector<Curve> folded_coons() {
  return {cubic({{-1, -1}, {-0.08, -1.42}, {1.13, -1.37}, {1, -1}}), cubic({{-1, 1}, {0.61, 1.22}, {0.14, 0.99}, {1, 1}}),
          cubic({{-1, -1}, {-0.52, 0.36}, {-1.11, 0.67}, {-1, 1}}), cubic({{1, -1}, {0.69, -0.19}, {1.29, -0.26}, {1, 1}})};
}

/// One that needs one added degree of freedom.
std::vector<Curve> folded_coons_2() {
  return {cubic({{-1, -1}, {1.10, -1.04}, {1.12, -1.36}, {1, -1}}), cubic({{-1, 1}, {1.47, 1.39}, {0.97, 1.07}, {1, 1}}),
          cubic({{-1, -1}, {-0.55, 0.04}, {-0.70, 0.40}, {-1, 1}}), cubic({{1, -1}, {0.69, -0.57}, {1.11, -0.06}, {1, 1}})};
}

void check_boolean_sum_boundaries(const Surface& s, const std::vector<Curve>& c) {
  CHECK(boundary_gap(s, 1, 0.0, c[0]) < 1e-12);
  CHECK(boundary_gap(s, 1, 1.0, c[1]) < 1e-12);
  CHECK(boundary_gap(s, 0, 0.0, c[2]) < 1e-12);
  CHECK(boundary_gap(s, 0, 1.0, c[3]) < 1e-12);
}

}  // namespace

TEST_CASE("kernel-based Boolean sum: valid where the Coons patch folds, same boundaries", "[kernel]") {
  const auto c = folded_coons();
  const Surface s0 = construct::regular_construct(KernelOp::boolean_sum, c);
  const auto r0 = det_range(s0);
  REQUIRE(r0[0] < 0.0);  // the regular construction folds: det J takes both signs
  REQUIRE(r0[1] > 0.0);

  for (AddDof how : {AddDof::refine, AddDof::elevate}) {
    construct::KernelConstructOptions o;
    o.add_dof = how;
    const auto r = construct::kernel_construct(KernelOp::boolean_sum, c, o);
    CHECK_FALSE(r.regular_valid);
    REQUIRE(r.valid);
    REQUIRE(r.kernel.has_value());
    CHECK(r.kernel_measure > 0.0);
    CHECK(r.reason.empty());
    const auto range = det_range(r.spline);
    CHECK(range[0] >= -1e-12 * range[1]);
    CHECK(range[1] > 0.0);
    CHECK(r.strictly_valid == (geom::check_validity(r.spline).verdict == geom::Validity::valid));
    check_boolean_sum_boundaries(r.spline, c);
    // Interior control points at K (xy), properties as the regular construction gave them.
    const Surface moved_from = r.iterations == 0 ? s0
                               : how == AddDof::refine
                                   ? spline::refine_uniform(spline::refine_uniform(s0, 0, r.iterations), 1, r.iterations)
                                   : spline::elevate(spline::elevate(s0, 0, r.iterations), 1, r.iterations);
    REQUIRE(moved_from.counts() == r.spline.counts());
    for (int i = 0; i < r.spline.size(); ++i) {
      const auto ij = r.spline.multi_index(i);
      const bool interior = ij[0] > 0 && ij[1] > 0 && ij[0] < r.spline.count(0) - 1 && ij[1] < r.spline.count(1) - 1;
      if (interior) {
        CHECK(r.spline.point(i)[0] == (*r.kernel)[0]);
        CHECK(r.spline.point(i)[1] == (*r.kernel)[1]);
      } else {
        CHECK(r.spline.point(i)[0] == Approx(moved_from.point(i)[0]).margin(1e-12));
      }
      CHECK(r.spline.point(i)[2] == Approx(moved_from.point(i)[2]).margin(1e-12));
    }
  }
}

TEST_CASE("kernel-based Boolean sum that needs added degrees of freedom", "[kernel]") {
  const auto c = folded_coons_2();
  REQUIRE(det_range(construct::regular_construct(KernelOp::boolean_sum, c))[0] < 0.0);
  construct::KernelConstructOptions o;
  o.max_dof = 0;
  const auto none = construct::kernel_construct(KernelOp::boolean_sum, c, o);
  CHECK_FALSE(none.valid);
  CHECK(none.kernel.has_value());
  CHECK_FALSE(none.reason.empty());
  CHECK(det_range(none.spline)[0] < 0.0);  // moving the interior to K alone is not enough
  o.max_dof = 20;
  const auto r = construct::kernel_construct(KernelOp::boolean_sum, c, o);
  REQUIRE(r.valid);
  CHECK(r.iterations >= 1);
  CHECK(r.spline.count(0) == 4 + r.iterations);  // i knots in the one span
  const auto range = det_range(r.spline);
  CHECK(range[0] >= -1e-12 * range[1]);
  check_boolean_sum_boundaries(r.spline, c);
}

TEST_CASE("Sec. 6: interior points spread on a grid around K give a positive Jacobian", "[kernel]") {
  const auto c = folded_coons_2();
  construct::KernelConstructOptions o;
  o.spread = 0.1;
  o.acceptance = construct::Acceptance::positive;
  const auto r = construct::kernel_construct(KernelOp::boolean_sum, c, o);
  REQUIRE(r.valid);
  CHECK(r.strictly_valid);
  CHECK(geom::check_validity(r.spline).verdict == geom::Validity::valid);
  CHECK(det_range(r.spline)[0] > 0.0);
  check_boolean_sum_boundaries(r.spline, c);
  // The grid is centred at K, 0.1 sqrt(area) wide along each (unit) axis; no two points coincide.
  const double half = 0.5 * 0.1 * std::sqrt(r.kernel_measure) * 2 + 1e-12;  // two unit axes, not orthogonal
  std::vector<Pt> inner;
  for (int i = 0; i < r.spline.size(); ++i) {
    const auto ij = r.spline.multi_index(i);
    if (ij[0] > 0 && ij[1] > 0 && ij[0] < r.spline.count(0) - 1 && ij[1] < r.spline.count(1) - 1) {
      const Pt p{r.spline.point(i)[0], r.spline.point(i)[1]};
      CHECK(std::hypot(p[0] - (*r.kernel)[0], p[1] - (*r.kernel)[1]) <= half);
      for (const Pt& q : inner) CHECK(std::hypot(p[0] - q[0], p[1] - q[1]) > 0.0);
      inner.push_back(p);
    }
  }
}

TEST_CASE("kernel-based half Boolean sum of two curves (Fadila et al. 2023, Lemma 1 boundaries)", "[kernel]") {
  const std::vector<Curve> c{cubic({{-1, -1}, {1.01, -1.40}, {0.61, -1.30}, {1, -1}}),
                             cubic({{-1, -1}, {-0.60, -0.65}, {-0.61, -1.04}, {-1, 1}})};
  REQUIRE(det_range(construct::regular_construct(KernelOp::half_boolean_sum, c))[0] < 0.0);
  const auto r = construct::kernel_construct(KernelOp::half_boolean_sum, c);
  REQUIRE(r.valid);
  CHECK(det_range(r.spline)[0] >= 0.0);
  CHECK(boundary_gap(r.spline, 1, 0.0, c[0]) < 1e-12);
  CHECK(boundary_gap(r.spline, 0, 0.0, c[1]) < 1e-12);
}

TEST_CASE("kernel-based ruling starts from a ruling at order 3 (Fadila et al. 2023, Sec. 5.1)", "[kernel]") {
  const std::vector<Curve> c{cubic({{-1, -1}, {-0.12, -1.01}, {-0.82, -1.11}, {1, -1}}),
                             cubic({{-1, 1}, {0.61, 0.53}, {-1.44, 1.49}, {1, 1}})};
  const Surface s0 = construct::regular_construct(KernelOp::ruled, c);
  CHECK(s0.orders() == std::array<int, 2>{4, 3});
  // Still the linear ruling (1 - v) bottom + v top, which folds here.
  for (double u : {0.1, 0.5, 0.9}) {
    const auto p = s0.eval({u, 0.3}), b = c[0].eval({u}), t = c[1].eval({u});
    for (int h = 0; h < 3; ++h) CHECK(p[static_cast<std::size_t>(h)] == Approx(0.7 * b[static_cast<std::size_t>(h)] + 0.3 * t[static_cast<std::size_t>(h)]));
  }
  REQUIRE(det_range(s0)[0] < 0.0);
  const auto r = construct::kernel_construct(KernelOp::ruled, c);
  REQUIRE(r.valid);
  CHECK(det_range(r.spline)[0] >= 0.0);
  CHECK(boundary_gap(r.spline, 1, 0.0, c[0]) < 1e-12);
  CHECK(boundary_gap(r.spline, 1, 1.0, c[1]) < 1e-12);
}

TEST_CASE("a valid regular construction is returned as it is; a boundary without kernel fails", "[kernel]") {
  const std::vector<Curve> square{cubic({{0, 0}, {1, 0}, {2, 0}, {3, 0}}), cubic({{0, 3}, {1, 3}, {2, 3}, {3, 3}}),
                                  cubic({{0, 0}, {0, 1}, {0, 2}, {0, 3}}), cubic({{3, 0}, {3, 1}, {3, 2}, {3, 3}})};
  const auto ok = construct::kernel_construct(KernelOp::boolean_sum, square);
  CHECK(ok.regular_valid);
  CHECK(ok.valid);
  CHECK(ok.iterations == 0);
  CHECK_FALSE(ok.kernel.has_value());
  CHECK(ok.spline == construct::regular_construct(KernelOp::boolean_sum, square));

  // A U: the top dips almost to the bottom. Its Coons patch folds and no point sees the
  // whole boundary (the two sides of the dip face away from each other).
  const std::vector<Curve> u{cubic({{-1, -1}, {-0.3, -1}, {0.3, -1}, {1, -1}}),
                             cubic({{-1, 1}, {-0.6, -2.2}, {0.6, -2.2}, {1, 1}}),
                             cubic({{-1, -1}, {-1, -0.3}, {-1, 0.3}, {-1, 1}}), cubic({{1, -1}, {1, -0.3}, {1, 0.3}, {1, 1}})};
  REQUIRE(det_range(construct::regular_construct(KernelOp::boolean_sum, u))[0] < 0.0);
  const auto bad = construct::kernel_construct(KernelOp::boolean_sum, u);
  CHECK_FALSE(bad.regular_valid);
  CHECK_FALSE(bad.valid);
  CHECK_FALSE(bad.kernel.has_value());
  CHECK(bad.reason.find("kernel") != std::string::npos);

  CHECK_THROWS_AS(construct::kernel_construct(KernelOp::boolean_sum, std::span<const Curve>(square.data(), 3)), Error);
  CHECK(construct::kernel_op_from_name("half_boolean_sum") == KernelOp::half_boolean_sum);
  CHECK_THROWS_AS(construct::kernel_op_from_name("coons"), Error);
}

TEST_CASE("kernel-based half Boolean sum trivariate (Fadila et al. 2023, Sec. 3.2, Lemma 2)", "[kernel]") {
  // s1(u,v) = (2u + 4v(1-v) b(u), v, 0), s2(u,w) = (2u + 4w(1-w) b(u), 0, w), b = 1.5 u (1 - u):
  // both faces are valid (x_u = 2 + 4t(1-t) b' >= 0.5), they share C(u) = (2u, 0, 0), and
  // T = s1 + s2 - C has det J = x_u = 2 + (4v(1-v) + 4w(1-w)) b'(u), which is -1 at
  // (1, 1/2, 1/2). T's boundary is the box [0,2] x [0,1] x [0,1] (x = 0 at u = 0, x = 2 at
  // u = 1), whose kernel is the box itself: centroid (1, 1/2, 1/2), volume 2.
  auto face = [](bool second) {
    std::vector<double> p;
    const double x[3] = {0, 1, 2}, b[3] = {0, 0.75, 0}, beta[3] = {0, 2, 0}, t[3] = {0, 0.5, 1};
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        const double xi = x[i] + beta[j] * b[i];
        if (second) p.insert(p.end(), {xi, 0, t[j]});
        else p.insert(p.end(), {xi, t[j], 0});
      }
    return Surface({KnotVector::bezier(3), KnotVector::bezier(3)}, 3, p);
  };
  const std::vector<Surface> s{face(false), face(true)};
  const Trivariate t0 = construct::regular_construct(KernelOp::half_boolean_sum, std::span<const Surface>(s));
  CHECK(det3(t0, {1.0, 0.5, 0.5}) == Approx(-1.0));

  for (AddDof how : {AddDof::refine, AddDof::elevate}) {
    construct::KernelConstructOptions o;
    o.add_dof = how;
    const auto r = construct::kernel_construct(KernelOp::half_boolean_sum, std::span<const Surface>(s), o);
    CHECK_FALSE(r.regular_valid);
    REQUIRE(r.kernel.has_value());
    CHECK((*r.kernel)[0] == Approx(1.0));
    CHECK((*r.kernel)[1] == Approx(0.5));
    CHECK((*r.kernel)[2] == Approx(0.5));
    CHECK(r.kernel_measure == Approx(2.0));
    REQUIRE(r.valid);
    double lo = HUGE_VAL;
    for (int i = 0; i <= 20; ++i)
      for (int j = 0; j <= 20; ++j)
        for (int k = 0; k <= 20; ++k) lo = std::min(lo, det3(r.spline, {i / 20.0, j / 20.0, k / 20.0}));
    CHECK(lo >= 0.0);
    // Lemma 2: T(u, v, 0) = s1(u, v), T(u, 0, w) = s2(u, w).
    double gap = 0.0;
    for (int i = 0; i <= 20; ++i)
      for (int j = 0; j <= 20; ++j) {
        const double a = i / 20.0, b = j / 20.0;
        const auto p = r.spline.eval({a, b, 0.0}), q = s[0].eval({a, b});
        const auto p2 = r.spline.eval({a, 0.0, b}), q2 = s[1].eval({a, b});
        for (int h = 0; h < 3; ++h) gap = std::max({gap, std::abs(p[h] - q[h]), std::abs(p2[h] - q2[h])});
      }
    CHECK(gap < 1e-12);
    // KernelPoint::fitted is accepted no later than the centroid (here already at iteration 0,
    // so the point stays the centroid), inside the kernel box, with the same boundaries.
    o.kernel_point = construct::KernelPoint::fitted;
    const auto f = construct::kernel_construct(KernelOp::half_boolean_sum, std::span<const Surface>(s), o);
    REQUIRE(f.valid);
    CHECK(f.iterations <= r.iterations);
    REQUIRE(f.point.has_value());
    CHECK((*f.point)[0] >= 0.0);
    CHECK((*f.point)[0] <= 2.0);
    CHECK((*f.point)[1] >= 0.0);
    CHECK((*f.point)[1] <= 1.0);
    CHECK((*f.point)[2] >= 0.0);
    CHECK((*f.point)[2] <= 1.0);
    CHECK(f.spline.eval({0.3, 0.7, 0.0})[0] == Approx(s[0].eval({0.3, 0.7})[0]).margin(1e-12));
  }
}

TEST_CASE("KernelPoint::fitted: a kernel point where det J's coefficients allow it (Fadila et al. 2023, Sec. 7)", "[kernel]") {
  // From the Sec. 5.1 generator (rounded): at the kernel centroid the Jacobian folds at
  // iteration 0; elsewhere in the kernel it does not.
  const std::vector<Curve> c{cubic({{-1, -1}, {0.72, -0.26}, {0.47, -1.13}, {1, -1}}),
                             cubic({{-1, 1}, {0.85, 1.35}, {1.07, 1.83}, {1, 1}}),
                             cubic({{-1, -1}, {-1.30, -0.44}, {-0.91, -0.43}, {-1, 1}}),
                             cubic({{1, -1}, {1.74, 0.46}, {0.04, -0.98}, {1, 1}})};
  construct::KernelConstructOptions o;
  o.max_dof = 0;
  const auto at_centroid = construct::kernel_construct(KernelOp::boolean_sum, c, o);
  REQUIRE_FALSE(at_centroid.regular_valid);
  REQUIRE(at_centroid.kernel.has_value());
  CHECK_FALSE(at_centroid.valid);
  CHECK_FALSE(at_centroid.fitted);
  CHECK(det_range(at_centroid.spline)[0] < 0.0);  // a real fold, not an artefact of the test

  o.kernel_point = construct::KernelPoint::fitted;
  const auto r = construct::kernel_construct(KernelOp::boolean_sum, c, o);
  REQUIRE(r.valid);
  CHECK(r.fitted);
  CHECK(r.iterations == 0);
  REQUIRE(r.point.has_value());
  CHECK(*r.point != *r.kernel);
  CHECK(*r.kernel == *at_centroid.kernel);  // `kernel` stays the centroid
  // The fitted point lies inside the (tighter, still conservative) kernel it is taken from.
  const auto kern = geom::planar_kernel(construct::regular_construct(KernelOp::boolean_sum, c), o.fit_kernel);
  for (std::size_t i = 0; i < kern.vertices.size(); ++i) {
    const auto& a = kern.vertices[i];
    const auto& b = kern.vertices[(i + 1) % kern.vertices.size()];
    CHECK((b[0] - a[0]) * ((*r.point)[1] - a[1]) - (b[1] - a[1]) * ((*r.point)[0] - a[0]) >= 0.0);
  }
  const auto range = det_range(r.spline);
  CHECK(range[0] >= -1e-12 * range[1]);
  CHECK(r.strictly_valid == (geom::check_validity(r.spline).verdict == geom::Validity::valid));
  check_boolean_sum_boundaries(r.spline, c);
  for (int row = 0; row < r.spline.size(); ++row) {
    const auto ij = r.spline.multi_index(row);
    if (ij[0] == 0 || ij[1] == 0 || ij[0] == r.spline.count(0) - 1 || ij[1] == r.spline.count(1) - 1) continue;
    CHECK(r.spline.point(row)[0] == (*r.point)[0]);
    CHECK(r.spline.point(row)[1] == (*r.point)[1]);
  }
}

TEST_CASE("KernelConstructOptions::retry_spread: the Sec. 6 grid around the fitted point as a last try", "[kernel]") {
  // From the Sec. 5.1 generator (rounded): neither the centroid nor a single fitted point gives
  // det J >= 0 at iteration 0; the interior spread on a small grid around a fitted centre does.
  const std::vector<Curve> c{cubic({{-1, -1}, {0.92, -1.77}, {0.61, -1.26}, {1, -1}}),
                             cubic({{-1, 1}, {1.94, 1.77}, {-1.82, 0.20}, {1, 1}}),
                             cubic({{-1, -1}, {-1.47, 0.22}, {-1.03, 0.98}, {-1, 1}}),
                             cubic({{1, -1}, {0.74, -0.26}, {1.15, -0.42}, {1, 1}})};
  construct::KernelConstructOptions o;
  o.max_dof = 0;
  o.kernel_point = construct::KernelPoint::fitted;
  const auto single = construct::kernel_construct(KernelOp::boolean_sum, c, o);
  REQUIRE(single.kernel.has_value());
  CHECK_FALSE(single.valid);
  CHECK(single.spread_width == 0.0);
  CHECK(det_range(single.spline)[0] < 0.0);

  o.retry_spread = 0.5;
  const auto r = construct::kernel_construct(KernelOp::boolean_sum, c, o);
  REQUIRE(r.valid);
  CHECK(r.iterations == 0);
  CHECK(r.fitted);
  CHECK(r.spread_width == Approx(0.5 * std::sqrt(r.kernel_measure)));
  const auto range = det_range(r.spline);
  CHECK(range[0] >= -1e-12 * range[1]);
  CHECK(r.strictly_valid == (geom::check_validity(r.spline).verdict == geom::Validity::valid));
  check_boolean_sum_boundaries(r.spline, c);
  // The interior points are distinct (a grid), centred at the fitted point.
  double cx = 0.0, cy = 0.0;
  int n = 0;
  for (int row = 0; row < r.spline.size(); ++row) {
    const auto ij = r.spline.multi_index(row);
    if (ij[0] == 0 || ij[1] == 0 || ij[0] == r.spline.count(0) - 1 || ij[1] == r.spline.count(1) - 1) continue;
    cx += r.spline.point(row)[0], cy += r.spline.point(row)[1], ++n;
  }
  CHECK(cx / n == Approx((*r.point)[0]).margin(1e-12));
  CHECK(cy / n == Approx((*r.point)[1]).margin(1e-12));
  CHECK(r.spline.point(r.spline.row({1, 1}))[0] != r.spline.point(r.spline.row({2, 2}))[0]);
}
