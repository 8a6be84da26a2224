// Faces cut by curves in their parameter space (geom/face_trim.hpp). Truths:
// - a planar face S(u, v) = (2u, 3v, 0) has area element 6: a region of parameter area A has area
//   6 A; a square hole leaves 6 (1 - a^2); a straight chord from (0.25, 0) to (0.75, 1) leaves
//   6 * 0.5 on its left; a quadratic Bezier chord v = 0.5 + 0.8 u (1 - u) leaves below it
//   6 (0.5 + 2/3 * 0.2) (a parabolic segment's area is 2/3 base x height);
// - a cubic B-spline approximation of a circle as a hole: the kept area is 6 (1 - A_c), A_c the
//   curve's own enclosed area by Green's theorem, 1/2 loop integral (u v' - v u') dt, with Gauss
//   points exact for the polynomial integrand (independent of the tracing and untrimming);
// - the regions of any arrangement tile the face: their areas add up to the face's area, also
//   for a curved (biquadratic) face, with chords, an island and an island inside the island;
// - four separate edges of a square, meeting end to end, are joined into one hole;
// - the predicate decides: keeping the complement gives the complementary area;
// - arrangements with crossings and junctions: two crossing chords (a plus sign) leave four
//   rectangles; a stem ending on a parabola's apex (a T) leaves the parabolic areas
//   1 - (0.5 + 2/3 0.2) above and 0.25 + 0.8/12 on each side below; three segments meeting end to
//   end at an interior point (a Y) leave three polygons of shoelace areas; a circle of four
//   cubic arcs crossed by a line through its centre, symmetric about it, leaves two half-discs
//   of A_c / 2 (A_c by Green's theorem on the arcs) and 0.5 - A_c / 2 outside; in every case the
//   regions' areas add up to the face's to 1e-12;
// - eleven random chords in general position cut the square into 1 + n + k regions (Euler's
//   formula, k the crossings counted from the segments' equations), tiling it;
// - a repeated curve and curves along the boundary change nothing;
// - refusals: an open curve ending inside the rectangle (the message names the face), a curve
//   crossing another and then ending in the open, an end 1e-3 short of the curve it should
//   meet; determinism: two runs give the same loops.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "trivox/error.hpp"
#include "trivox/geom/face_trim.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/geom/trimmed_surface.hpp"

using namespace trivox;
using geom::FaceTrimOptions;
using spline::Curve;
using spline::KnotVector;
using spline::Surface;

namespace {

using Pt = std::array<double, 2>;

Surface planar_face() {
  // S(u, v) = (2u, 3v, 0) on [0, 1]^2, bilinear.
  return Surface({KnotVector::bezier(2), KnotVector::bezier(2)}, 3,
                 std::vector<double>{0, 0, 0, 2, 0, 0, 0, 3, 0, 2, 3, 0});
}

Surface curved_face() {
  // A biquadratic bump with parameter rectangle [0, 2] x [0, 3].
  std::vector<double> p;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) p.insert(p.end(), {1.0 * i, 1.5 * j, (i == 1 && j == 1) ? 1.5 : 0.2 * i * j});
  return Surface({KnotVector::bezier(3, 0.0, 2.0), KnotVector::bezier(3, 0.0, 3.0)}, 3, p);
}

Curve polyline(const std::vector<Pt>& p) {
  // A degree-1 B-spline through the points (closed when the last equals the first).
  std::vector<double> k{0, 0};
  for (std::size_t i = 1; i + 1 < p.size(); ++i) k.push_back(static_cast<double>(i));
  k.push_back(static_cast<double>(p.size() - 1));
  k.push_back(static_cast<double>(p.size() - 1));
  std::vector<double> c;
  for (const auto& q : p) c.insert(c.end(), {q[0], q[1]});
  return Curve({KnotVector(2, k)}, 2, c);
}

Curve circle_like(Pt centre, double r) {
  // Clamped cubic B-spline whose first and last control points coincide: a closed curve inside
  // the circle of radius r on which its control points lie.
  const int n = 8;
  std::vector<double> c;
  const double pi = std::acos(-1.0);
  for (int i = 0; i <= n; ++i) {
    const double a = 2 * pi * i / n;
    c.insert(c.end(), {centre[0] + r * std::cos(a), centre[1] + r * std::sin(a)});
  }
  return Curve({KnotVector::uniform(4, n - 2)}, 2, c);
}

double green_area(const Curve& c) {
  const auto g = geom::gauss_legendre(8);
  const auto& kv = c.knots(0);
  double a = 0;
  for (std::size_t i = 0; i + 1 < kv.knots().size(); ++i) {
    const double t0 = kv.knots()[i], t1 = kv.knots()[i + 1];
    if (!(t1 > t0) || t0 < kv.front() || t1 > kv.back()) continue;
    for (std::size_t q = 0; q < g.nodes.size(); ++q) {
      const double t = 0.5 * (t0 + t1) + 0.5 * (t1 - t0) * g.nodes[q];
      const auto d = c.eval_derivatives({t}, 1);  // u, v, u', v'
      a += 0.5 * (t1 - t0) * g.weights[q] * 0.5 * (d[0] * d[3] - d[1] * d[2]);
    }
  }
  return a;
}

double total(const std::vector<geom::TrimmedSurface>& s) {
  double a = 0;
  for (const auto& t : s) a += geom::area(t);
  return a;
}

/// Two runs gave the same regions: interior points and loops, piece for piece.
void same_regions(const std::vector<geom::FaceRegion>& again, const std::vector<geom::FaceRegion>& regions) {
  REQUIRE(again.size() == regions.size());
  for (std::size_t i = 0; i < regions.size(); ++i) {
    CHECK(again[i].u == regions[i].u);
    CHECK(again[i].v == regions[i].v);
    REQUIRE(again[i].surface.loops().size() == regions[i].surface.loops().size());
    for (std::size_t k = 0; k < regions[i].surface.loops().size(); ++k)
      CHECK(again[i].surface.loops()[k].pieces == regions[i].surface.loops()[k].pieces);
  }
}

}  // namespace

TEST_CASE("trim_face: a square hole in a planar face", "[face_trim]") {
  const double a = 0.4;
  const Curve sq = polyline({{0.3, 0.3}, {0.3 + a, 0.3}, {0.3 + a, 0.3 + a}, {0.3, 0.3 + a}, {0.3, 0.3}});
  auto outside = [&](const double* x) {
    const double u = x[0] / 2, v = x[1] / 3;
    return !(u > 0.3 && u < 0.3 + a && v > 0.3 && v < 0.3 + a);
  };
  const auto regions = geom::face_regions(planar_face(), {sq}, outside);
  REQUIRE(regions.size() == 2);
  CHECK(regions[0].kept);
  CHECK_FALSE(regions[1].kept);
  const auto kept = geom::trim_face(planar_face(), {sq}, outside);
  REQUIRE(kept.size() == 1);
  const double got = total(kept);
  std::printf("square hole: area %.15g, expected %.15g\n", got, 6 * (1 - a * a));
  CHECK(std::abs(got - 6 * (1 - a * a)) <= 1e-8 * 6);
  // The complement.
  const auto inner = geom::trim_face(planar_face(), {sq}, [&](const double* x) { return !outside(x); });
  REQUIRE(inner.size() == 1);
  CHECK(std::abs(total(inner) - 6 * a * a) <= 1e-8 * 6);
}

TEST_CASE("trim_face: a square hole from four separate edges, joined end to end", "[face_trim]") {
  // The edges in scrambled order and directions, as intersections with the four side faces of a
  // box through the face would come.
  const std::vector<Curve> edges{polyline({{0.7, 0.3}, {0.7, 0.7}}), polyline({{0.3, 0.3}, {0.3, 0.7}}),
                                 polyline({{0.7, 0.7}, {0.3, 0.7}}), polyline({{0.7, 0.3}, {0.3, 0.3}})};
  auto outside = [](const double* x) {
    const double u = x[0] / 2, v = x[1] / 3;
    return !(u > 0.3 && u < 0.7 && v > 0.3 && v < 0.7);
  };
  const auto regions = geom::face_regions(planar_face(), edges, outside);
  REQUIRE(regions.size() == 2);
  const auto kept = geom::trim_face(planar_face(), edges, outside);
  REQUIRE(kept.size() == 1);
  REQUIRE(kept[0].loops().size() == 2);
  CHECK(kept[0].loops()[1].pieces.size() == 4);
  std::printf("square hole from four edges: area %.15g, expected %.15g\n", total(kept), 6 * (1 - 0.16));
  CHECK(std::abs(total(kept) - 6 * (1 - 0.16)) <= 1e-8 * 6);
  // Three edges leave a dangling chain: refused.
  CHECK_THROWS_AS(geom::trim_face(planar_face(), {edges[0], edges[1], edges[2]}, outside), Error);
}

TEST_CASE("trim_face: straight and curved chords", "[face_trim]") {
  const Curve chord = polyline({{0.25, 0.0}, {0.75, 1.0}});
  auto left = [](const double* x) { return x[0] / 2 < 0.25 + 0.5 * x[1] / 3; };
  const auto l = geom::trim_face(planar_face(), {chord}, left);
  REQUIRE(l.size() == 1);
  CHECK(std::abs(total(l) - 3.0) <= 1e-8 * 6);
  // The chord reversed gives the same region.
  const Curve rev = polyline({{0.75, 1.0}, {0.25, 0.0}});
  CHECK(std::abs(total(geom::trim_face(planar_face(), {rev}, left)) - 3.0) <= 1e-8 * 6);

  const Curve arc({KnotVector::bezier(3)}, 2, std::vector<double>{0, 0.5, 0.5, 0.9, 1, 0.5});
  auto below = [](const double* x) {
    const double u = x[0] / 2, v = x[1] / 3;
    return v < 0.5 + 0.8 * u * (1 - u);
  };
  const auto b = geom::trim_face(planar_face(), {arc}, below);
  REQUIRE(b.size() == 1);
  const double expected = 6 * (0.5 + 2.0 / 3.0 * 0.2);
  std::printf("parabolic chord: area %.15g, expected %.15g\n", total(b), expected);
  CHECK(std::abs(total(b) - expected) <= 1e-8 * 6);
}

TEST_CASE("trim_face: a cubic circle as a hole, area by Green's theorem", "[face_trim]") {
  const Curve c = circle_like({0.5, 0.5}, 0.3);
  const double ac = green_area(c);
  const double pi = std::acos(-1.0);
  REQUIRE(ac > 0.7 * pi * 0.09);  // inside its control polygon, itself inside the circle
  REQUIRE(ac < pi * 0.09);
  // The classification point of each region lies far from the curve, so the circle of radius
  // 0.3 around the curve serves as the predicate.
  auto outside = [](const double* x) { return std::hypot(x[0] / 2 - 0.5, x[1] / 3 - 0.5) > 0.3; };
  const auto kept = geom::trim_face(planar_face(), {c}, outside);
  REQUIRE(kept.size() == 1);
  std::printf("cubic circle hole: area %.15g, expected 6 (1 - %.15g) = %.15g\n", total(kept), ac, 6 * (1 - ac));
  CHECK(std::abs(total(kept) - 6 * (1 - ac)) <= 1e-8 * 6);
}

TEST_CASE("trim_face: the regions tile a curved face", "[face_trim]") {
  const Surface f = curved_face();
  const std::vector<Curve> cuts{
      polyline({{0.0, 0.5}, {0.8, 1.2}, {2.0, 0.7}}),       // chord left -> right
      polyline({{1.5, 3.0}, {1.7, 2.0}, {2.0, 1.8}}),       // chord top -> right, a corner cut
      circle_like({0.8, 2.0}, 0.5),                         // island
      circle_like({0.8, 2.0}, 0.2),                         // island inside the island
  };
  const auto regions = geom::face_regions(f, cuts, [](const double*) { return true; });
  REQUIRE(regions.size() == 5);
  double sum = 0;
  for (const auto& r : regions) sum += geom::area(r.surface);
  const double whole = geom::surface_area(f, 16);
  std::printf("curved face: regions' areas sum %.15g, face area %.15g\n", sum, whole);
  CHECK(std::abs(sum - whole) <= 1e-8 * whole);
  // The ring between the islands and the inner disc are the last two regions.
  CHECK(regions[3].surface.loops().size() == 2);
  CHECK(regions[4].surface.loops().size() == 1);
  // Determinism.
  same_regions(geom::face_regions(f, cuts, [](const double*) { return true; }), regions);
}

TEST_CASE("trim_face: refusals", "[face_trim]") {
  FaceTrimOptions o;
  o.face_name = "cell 3, face w+";
  const Curve dangling = polyline({{0.0, 0.5}, {0.6, 0.5}});
  try {
    geom::trim_face(planar_face(), {dangling}, [](const double*) { return true; }, o);
    FAIL("no error");
  } catch (const Error& e) {
    const std::string m = e.what();
    CHECK(m.find("cell 3, face w+") != std::string::npos);
    CHECK(m.find("open") != std::string::npos);
  }
  // A curve that crosses another and then ends in the open dangles.
  const Curve a = polyline({{0.0, 0.5}, {1.0, 0.5}});
  const Curve b = polyline({{0.5, 0.0}, {0.5, 0.8}});
  try {
    geom::trim_face(planar_face(), {a, b}, [](const double*) { return true; }, o);
    FAIL("no error");
  } catch (const Error& e) {
    const std::string m = e.what();
    CHECK(m.find("cutting curve 1 is open") != std::string::npos);
  }
  // A stem stopping 1e-3 short of the bar meets nothing either.
  const Curve short_stem = polyline({{0.5, 0.0}, {0.5, 0.499}});
  CHECK_THROWS_AS(geom::trim_face(planar_face(), {a, short_stem}, [](const double*) { return true; }, o), Error);
}

namespace {

/// Checks each region's area against the expected parameter area (times the area element 6) of
/// the region holding its interior point, and that the areas add up to the face's 6.
void check_regions(const std::vector<geom::FaceRegion>& regions, double (*expected)(double u, double v), const char* what) {
  double sum = 0;
  for (const auto& r : regions) {
    const double a = geom::area(r.surface), e = 6 * expected(r.u, r.v);
    std::printf("%s: region at (%.4f, %.4f): area %.15g, expected %.15g\n", what, r.u, r.v, a, e);
    CHECK(std::abs(a - e) <= 1e-12 * 6);
    sum += a;
  }
  std::printf("%s: %zu regions, areas sum %.17g (face 6)\n", what, regions.size(), sum);
  CHECK(std::abs(sum - 6) <= 1e-12 * 6);
}

auto all = [](const double*) { return true; };

/// The cubic Bezier arc of radius r about c from angle a0 through 90 degrees (k = 4/3 tan(pi/8)).
Curve quarter(Pt c, double r, double a0) {
  const double a1 = a0 + std::acos(-1.0) / 2, k = 4.0 / 3.0 * std::tan(std::acos(-1.0) / 8);
  return Curve({KnotVector::bezier(4)}, 2,
               std::vector<double>{c[0] + r * std::cos(a0), c[1] + r * std::sin(a0),
                                   c[0] + r * std::cos(a0) - k * r * std::sin(a0), c[1] + r * std::sin(a0) + k * r * std::cos(a0),
                                   c[0] + r * std::cos(a1) + k * r * std::sin(a1), c[1] + r * std::sin(a1) - k * r * std::cos(a1),
                                   c[0] + r * std::cos(a1), c[1] + r * std::sin(a1)});
}

}  // namespace

TEST_CASE("trim_face: two crossing chords, a plus sign, give four rectangles", "[face_trim]") {
  // u = 0.3 and v = 0.6 cross inside their polyline segments; u = 0.25 and v = 0.625 cross at
  // a polyline point of both (16 samples per span).
  {
    const std::vector<Curve> plus{polyline({{0.3, 0.0}, {0.3, 1.0}}), polyline({{1.0, 0.6}, {0.0, 0.6}})};
    const auto regions = geom::face_regions(planar_face(), plus, all);
    REQUIRE(regions.size() == 4);
    check_regions(regions, [](double u, double v) { return (u < 0.3 ? 0.3 : 0.7) * (v < 0.6 ? 0.6 : 0.4); }, "plus");
  }
  {
    const std::vector<Curve> plus{polyline({{0.25, 0.0}, {0.25, 1.0}}), polyline({{0.0, 0.625}, {1.0, 0.625}})};
    const auto regions = geom::face_regions(planar_face(), plus, all);
    REQUIRE(regions.size() == 4);
    check_regions(regions, [](double u, double v) { return (u < 0.25 ? 0.25 : 0.75) * (v < 0.625 ? 0.625 : 0.375); }, "plus at samples");
    // Keeping the lower left quarter only.
    const auto kept = geom::trim_face(planar_face(), plus, [](const double* x) { return x[0] / 2 < 0.25 && x[1] / 3 < 0.625; });
    REQUIRE(kept.size() == 1);
    CHECK(std::abs(total(kept) - 6 * 0.25 * 0.625) <= 1e-12 * 6);
  }
}

TEST_CASE("trim_face: T and Y junctions", "[face_trim]") {
  // T: the parabola v = 0.5 + 0.8 u (1 - u) (a quadratic Bezier chord) and a stem u = 0.5 from
  // the bottom up to the parabola's apex (0.5, 0.7), an interior point of the parabola. Above:
  // 1 - (0.5 + 2/3 0.2); each side below: int_0^0.5 (0.5 + 0.8 u (1 - u)) du = 0.25 + 0.8/12.
  const Curve bar({KnotVector::bezier(3)}, 2, std::vector<double>{0, 0.5, 0.5, 0.9, 1, 0.5});
  const Curve stem = polyline({{0.5, 0.0}, {0.5, 0.7}});
  for (int order = 0; order < 2; ++order) {
    const std::vector<Curve> t = order ? std::vector<Curve>{stem, bar} : std::vector<Curve>{bar, stem};
    const auto regions = geom::face_regions(planar_face(), t, all);
    REQUIRE(regions.size() == 3);
    check_regions(regions, [](double u, double v) { return v > 0.5 + 0.8 * u * (1 - u) ? 1 - (0.5 + 2.0 / 3 * 0.2) : 0.25 + 0.8 / 12; }, "T");
  }
  // Y: three segments from the boundary points (0.4, 1), (0, 0), (1, 0.2) meeting end to end at
  // P = (0.4, 0.5); each region's area by the shoelace formula of its polygon.
  const std::vector<Curve> y{polyline({{0.4, 0.5}, {0.4, 1.0}}), polyline({{0.0, 0.0}, {0.4, 0.5}}), polyline({{0.4, 0.5}, {1.0, 0.2}})};
  const auto regions = geom::face_regions(planar_face(), y, all);
  REQUIRE(regions.size() == 3);
  check_regions(regions, [](double u, double v) {
    auto shoelace = [](std::vector<Pt> p) {
      double a = 0;
      for (std::size_t i = 0; i < p.size(); ++i) a += p[i][0] * p[(i + 1) % p.size()][1] - p[(i + 1) % p.size()][0] * p[i][1];
      return 0.5 * a;
    };
    const bool right = (u - 0.4) * 0.3 + (v - 0.5) * 0.6 > 0 && u > 0.4;  // above the segment to (1, 0.2), right of u = 0.4
    const bool lower = !right && (u - 0.4) * 0.5 - (v - 0.5) * 0.4 > 0;  // below the segment from (0, 0)
    if (right) return shoelace({{0.4, 0.5}, {1, 0.2}, {1, 1}, {0.4, 1}});
    if (lower) return shoelace({{0, 0}, {1, 0}, {1, 0.2}, {0.4, 0.5}});
    return shoelace({{0, 0}, {0.4, 0.5}, {0.4, 1}, {0, 1}});
  }, "Y");
}

TEST_CASE("trim_face: a circle of four arcs crossed by a line", "[face_trim]") {
  // Four cubic arcs of radius 0.3 about (0.5, 0.5), given as separate curves, and the chord
  // v = 0.5. The arcs are symmetric about that line, so each half-disc is A_c / 2, A_c the
  // arcs' area by Green's theorem; the parts above and below outside the circle 0.5 - A_c / 2.
  // First the arcs start at 45 degrees (the line crosses two arcs inside), then at 0 degrees
  // (the line passes through the points where arcs meet).
  const double pi = std::acos(-1.0);
  for (double a0 : {pi / 4, 0.0}) {
    std::vector<Curve> cuts{polyline({{0.0, 0.5}, {1.0, 0.5}})};
    double ac = 0;
    for (int q = 0; q < 4; ++q) {
      cuts.push_back(quarter({0.5, 0.5}, 0.3, a0 + q * pi / 2));
      ac += green_area(cuts.back());
    }
    REQUIRE(std::abs(ac - pi * 0.09) < 1e-3);
    const auto regions = geom::face_regions(planar_face(), cuts, all);
    REQUIRE(regions.size() == 4);
    static double half;
    half = ac / 2;
    check_regions(regions, [](double u, double v) { return std::hypot(u - 0.5, v - 0.5) < 0.3 ? half : 0.5 - half; },
                  a0 > 0 ? "circle crossed inside arcs" : "circle crossed at arc ends");
    // Determinism: the same regions, points and loops again.
    same_regions(geom::face_regions(planar_face(), cuts, all), regions);
  }
}

TEST_CASE("trim_face: repeated curves and curves along the boundary add nothing", "[face_trim]") {
  // The same square's edges twice (once reversed), a curve along the bottom side and one along
  // the right side: still a square hole, 6 (1 - 0.16).
  const std::vector<Curve> cuts{polyline({{0.3, 0.3}, {0.7, 0.3}, {0.7, 0.7}, {0.3, 0.7}, {0.3, 0.3}}),
                                polyline({{0.0, 0.0}, {0.6, 0.0}}),
                                polyline({{0.3, 0.3}, {0.3, 0.7}, {0.7, 0.7}, {0.7, 0.3}, {0.3, 0.3}}),
                                polyline({{1.0, 0.1}, {1.0, 0.9}}),
                                polyline({{0.7, 0.3}, {0.7, 0.7}})};
  const auto regions = geom::face_regions(planar_face(), cuts, all);
  REQUIRE(regions.size() == 2);
  check_regions(regions, [](double u, double v) { return (u > 0.3 && u < 0.7 && v > 0.3 && v < 0.7) ? 0.16 : 0.84; }, "repeated");
}

TEST_CASE("trim_face: random chords give 1 + n + k regions tiling the face", "[face_trim]") {
  // n straight chords between random points of the left and right sides (and of the bottom and
  // top sides), in general position: by Euler's formula the square is cut into 1 + n + k regions,
  // k the number of pairs crossing inside (counted from the lines' equations), and the areas add
  // up to the face's.
  std::uint64_t state = 12345;
  auto next = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return 0.05 + 0.9 * static_cast<double>(state >> 11) / 9007199254740992.0;
  };
  std::vector<std::array<Pt, 2>> seg;
  for (int i = 0; i < 6; ++i) seg.push_back({Pt{0.0, next()}, Pt{1.0, next()}});
  for (int i = 0; i < 5; ++i) seg.push_back({Pt{next(), 0.0}, Pt{next(), 1.0}});
  std::vector<Curve> cuts;
  for (const auto& s : seg) cuts.push_back(polyline({s[0], s[1]}));
  int k = 0;
  for (std::size_t a = 0; a < seg.size(); ++a)
    for (std::size_t b = a + 1; b < seg.size(); ++b) {
      auto side = [](Pt p, Pt q, Pt r) { return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]); };
      const auto& A = seg[a];
      const auto& B = seg[b];
      if (side(A[0], A[1], B[0]) * side(A[0], A[1], B[1]) < 0 && side(B[0], B[1], A[0]) * side(B[0], B[1], A[1]) < 0) ++k;
    }
  const auto regions = geom::face_regions(planar_face(), cuts, all);
  double sum = 0;
  for (const auto& r : regions) sum += geom::area(r.surface);
  std::printf("random chords: %zu chords, %d crossings, %zu regions (expected %zu), areas sum %.17g\n", seg.size(), k,
              regions.size(), 1 + seg.size() + static_cast<std::size_t>(k), sum);
  CHECK(regions.size() == 1 + seg.size() + static_cast<std::size_t>(k));
  CHECK(std::abs(sum - 6) <= 1e-12 * 6);
}
