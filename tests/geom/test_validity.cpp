// Jacobian validity (geom/validity.hpp). Truths: an affine map's determinant is det A everywhere;
// the bounds enclose det J computed independently from first partials at random points; a folded
// cell's reported invalid point has det J <= 0 there (independently evaluated); a collapsed face
// has det J = 0.
#include <catch2/catch.hpp>

#include <random>

#include "trivox/error.hpp"
#include "trivox/geom/validity.hpp"

using namespace trivox;
using spline::KnotVector;
using spline::Surface;
using spline::Trivariate;

namespace {

KnotVector bezier(int order) {
  std::vector<double> k(static_cast<std::size_t>(order), 0.0);
  k.resize(static_cast<std::size_t>(2 * order), 1.0);
  return KnotVector(order, k);
}

/// A tricubic Bezier cell with control points f(i/3, j/3, k/3) for an xyz map f.
template <class F>
Trivariate tricubic(F f) {
  std::vector<double> pts;
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        const auto p = f(i / 3.0, j / 3.0, k / 3.0);
        pts.insert(pts.end(), p.begin(), p.end());
      }
  return Trivariate({bezier(4), bezier(4), bezier(4)}, 3, pts);
}

/// det[dX/du, dX/dv, dX/dw] from the spline's first partials.
double det_at(const Trivariate& s, const std::array<double, 3>& t) {
  const auto v = s.eval_derivatives(t, 1);  // value, d/du, d/dv, d/dw; 3 coordinates each
  const double* a = v.data() + 3;
  const double* b = v.data() + 6;
  const double* c = v.data() + 9;
  return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
}

void check_bounds_enclose(const Trivariate& s, const geom::ValidityReport<3>& r) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int n = 0; n < 500; ++n) {
    const double d = det_at(s, {u(rng), u(rng), u(rng)});
    CHECK(d >= r.min_bound - 1e-9 * std::abs(r.min_bound));
    CHECK(d <= r.max_bound + 1e-9 * std::abs(r.max_bound));
  }
}

}  // namespace

TEST_CASE("an affine cell is valid with det J = det A exactly, oriented by its sign", "[validity]") {
  // x = 2u + v, y = 3v + w, z = u + 4w: det A = 2*(12 - 0) - 1*(0 - 1) + 0 = 25.
  const auto s = tricubic([](double u, double v, double w) { return std::array<double, 3>{2 * u + v, 3 * v + w, u + 4 * w}; });
  const auto r = geom::check_validity(s);
  CHECK(r.verdict == geom::Validity::valid);
  CHECK(r.orientation == 1);
  // The determinant spline comes from product splines, exact to about 1e-9 relative.
  CHECK(r.min_bound == Approx(25).epsilon(1e-8));
  CHECK(r.max_bound == Approx(25).epsilon(1e-8));
  CHECK(r.min_seen == Approx(25).epsilon(1e-8));
  CHECK(!r.invalid_at);
  // Mirrored in x: left-handed, still a valid parametrisation.
  const auto m = tricubic([](double u, double v, double w) { return std::array<double, 3>{-(2 * u + v), 3 * v + w, u + 4 * w}; });
  const auto rm = geom::check_validity(m);
  CHECK(rm.verdict == geom::Validity::valid);
  CHECK(rm.orientation == -1);
  CHECK(rm.max_bound == Approx(-25).epsilon(1e-8));
}

TEST_CASE("a curved valid cell: bounds enclose det J everywhere", "[validity]") {
  // A twisted, tapered column: valid (det J > 0) but far from affine.
  const auto s = tricubic([](double u, double v, double w) {
    const double a = 0.6 * w, r = 1.0 + 0.3 * w * w;
    const double x = r * (u - 0.5), y = r * (v - 0.5);
    return std::array<double, 3>{std::cos(a) * x - std::sin(a) * y, std::sin(a) * x + std::cos(a) * y, 2 * w + 0.1 * u * v};
  });
  const auto r = geom::check_validity(s);
  CHECK(r.verdict == geom::Validity::valid);
  CHECK(r.min_bound > 0);
  CHECK(r.min_bound <= r.min_seen);
  CHECK(r.max_seen <= r.max_bound);
  check_bounds_enclose(s, r);
}

TEST_CASE("a folded cell is invalid, at a point where det J really has the wrong sign", "[validity]") {
  // x's control polygon along u: 0, 1/3, -1.5, 1 in every row: x' < 0 around u = 1/2 (x'(1/2)
  // = 3 (1/3 / 4 - 11/6 / 2 + 5/2 / 4) = -5/8), so the map folds over.
  auto s = tricubic([](double u, double v, double w) { return std::array<double, 3>{u > 0.5 && u < 0.9 ? -1.5 : u, v, w}; });
  const auto r = geom::check_validity(s);
  REQUIRE(r.verdict == geom::Validity::invalid);
  REQUIRE(r.invalid_at);
  // det J < 0 at the centre (the orientation), > 0 at the corners: invalid where it is >= 0.
  CHECK(r.orientation == -1);
  CHECK(det_at(s, *r.invalid_at) * r.orientation <= 1e-12);
  CHECK(r.det_at_invalid == Approx(det_at(s, *r.invalid_at)).margin(1e-9));
  CHECK(r.min_bound < 0);
  CHECK(r.max_bound > 0);
  check_bounds_enclose(s, r);
  // Deterministic: the same first invalid point every time.
  const auto again = geom::check_validity(s);
  CHECK(*again.invalid_at == *r.invalid_at);
}

TEST_CASE("a collapsed face or edge is a degenerate boundary; a zero inside is invalid", "[validity]") {
  // x = u, y = u v, z = w: the face u = 0 collapses to a segment, det J = u: > 0 inside, 0 on
  // that face only.
  const auto s = tricubic([](double u, double v, double w) { return std::array<double, 3>{u, u * v, w}; });
  const auto r = geom::check_validity(s);
  REQUIRE(r.verdict == geom::Validity::degenerate);
  CHECK(std::string(geom::validity_name(r.verdict)) == "degenerate");
  CHECK(r.orientation == 1);
  REQUIRE(r.degenerate_at);
  CHECK((*r.degenerate_at)[0] == 0.0);
  CHECK(det_at(s, *r.degenerate_at) == Approx(0).margin(1e-14));
  CHECK_FALSE(r.invalid_at);
  CHECK(r.min_bound == Approx(0).margin(1e-12));
  CHECK(r.zero_tolerance > 0);
  CHECK(r.zero_tolerance < 1e-9);
  check_bounds_enclose(s, r);
  // x = u, y = u v, z = u w: the face u = 0 collapses to a point, det J = u^2.
  const auto apex = tricubic([](double u, double v, double w) { return std::array<double, 3>{u, u * v, u * w}; });
  const auto a = geom::check_validity(apex);
  CHECK(a.verdict == geom::Validity::degenerate);
  REQUIRE(a.degenerate_at);
  CHECK((*a.degenerate_at)[0] == 0.0);
  // Left-handed with a collapsed face: degenerate too, with orientation -1.
  const auto left = tricubic([](double u, double v, double w) { return std::array<double, 3>{u * v, u, w}; });
  const auto l = geom::check_validity(left);
  CHECK(l.verdict == geom::Validity::degenerate);
  CHECK(l.orientation == -1);
  // x = (u - 1/2)^3 (Bezier coefficients -1/8, 1/8, -1/8, 1/8 along u), y = v, z = w:
  // det J = 3 (u - 1/2)^2 >= 0, but 0 on the plane u = 1/2 inside the domain: invalid there (the
  // map is not locally invertible).
  const auto inner = tricubic([](double u, double v, double w) {
    static constexpr double c[4] = {-0.125, 0.125, -0.125, 0.125};
    return std::array<double, 3>{c[std::lround(3 * u)], v, w};
  });
  CHECK(det_at(inner, {0.5, 0.3, 0.7}) == Approx(0).margin(1e-15));
  CHECK(det_at(inner, {0.2, 0.3, 0.7}) == Approx(3 * 0.09).epsilon(1e-12));
  const auto i = geom::check_validity(inner);
  REQUIRE(i.verdict == geom::Validity::invalid);
  REQUIRE(i.invalid_at);
  CHECK((*i.invalid_at)[0] == Approx(0.5).margin(1e-12));
  CHECK(i.det_at_invalid == Approx(0).margin(1e-12));
  // x with control points u^2 - u/2 at u = i/3, i.e. x = u^2 - u/2 + u (1 - u) / 3: dx/du =
  // 4u/3 - 1/6 < 0 for u < 1/8, > 0 beyond: det J takes both signs, invalid (not degenerate)
  // though it is small near the face u = 0.
  const auto folded = tricubic([](double u, double v, double w) { return std::array<double, 3>{u * u - 0.5 * u, v, w}; });
  CHECK(geom::check_validity(folded).verdict == geom::Validity::invalid);
}

TEST_CASE("planar surfaces: a convex quad is valid, a bow tie is not", "[validity]") {
  const Surface quad({bezier(2), bezier(2)}, 2, {0, 0, 2, 0, 0, 1, 3, 2});
  const auto r = geom::check_validity(quad);
  CHECK(r.verdict == geom::Validity::valid);
  CHECK(r.orientation == 1);
  // Bilinear: det J = (2 + v) (1 + u) - (u)(...)...: its exact range is enclosed by the bounds.
  CHECK(r.min_bound > 0);
  const Surface bowtie({bezier(2), bezier(2)}, 2, {0, 0, 2, 0, 2, 1, 0, 1.2});  // top corners swapped
  const auto b = geom::check_validity(bowtie);
  CHECK(b.verdict == geom::Validity::invalid);
}

TEST_CASE("rational cells are refused with a reason", "[validity]") {
  std::vector<double> pts, w;
  for (int i = 0; i < 8; ++i) pts.insert(pts.end(), {double(i & 1), double((i >> 1) & 1), double((i >> 2) & 1)}), w.push_back(1.0 + i);
  const Trivariate s({bezier(2), bezier(2), bezier(2)}, 3, pts, w);
  try {
    geom::check_validity(s);
    FAIL("no error");
  } catch (const Error& e) {
    CHECK_THAT(e.what(), Catch::Contains("rational"));
  }
}

TEST_CASE("Massarwi & Elber 2016, Fig. 1b: interior control points pushed out of the cuboid are found invalid there", "[validity]") {
  // A triquadratic B-spline unit cube (5 x 5 x 5 control points at the Greville abscissae, so
  // X(u,v,w) = (u,v,w) and det J = 1), then three interior control points of the top inner
  // layer (k = 3) pushed up and out of the cuboid to z = 2.5.
  const KnotVector kv(3, {0, 0, 0, 1.0 / 3, 2.0 / 3, 1, 1, 1});
  const auto g = kv.greville();
  std::vector<double> pts;
  for (int k = 0; k < 5; ++k)
    for (int j = 0; j < 5; ++j)
      for (int i = 0; i < 5; ++i) pts.insert(pts.end(), {g[i], g[j], g[k]});
  Trivariate cube({kv, kv, kv}, 3, pts);
  REQUIRE(geom::check_validity(cube).verdict == geom::Validity::valid);
  for (auto [i, j] : {std::pair{1, 2}, std::pair{2, 2}, std::pair{2, 1}}) cube.point(cube.row({i, j, 3}))[2] = 2.5;
  const auto r = geom::check_validity(cube);
  CHECK(r.verdict == geom::Validity::invalid);
  REQUIRE(r.invalid_at);
  const auto t = *r.invalid_at;
  INFO("invalid at (" << t[0] << ", " << t[1] << ", " << t[2] << "), det " << r.det_at_invalid);
  // The place: where the moved points act (their basis functions' supports: u, v in (0, 1),
  // w in the last two spans, (1/3, 1]), with det J <= 0 by an independent evaluation.
  CHECK(t[2] > 1.0 / 3);
  CHECK(det_at(cube, t) <= 1e-9);
  CHECK(r.det_at_invalid <= 0.0);
  // Elsewhere the cell is untouched: det J = 1 where no moved point acts (w < 1/3).
  CHECK(det_at(cube, {0.5, 0.5, 0.2}) == Approx(1.0));
}
