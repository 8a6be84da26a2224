// Iso-curves, iso-surfaces, boundary faces and bounding boxes.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "poly.hpp"
#include "trivox/error.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/refine.hpp"

using namespace trivox::spline;
using trivox::test::random_params;
using trivox::test::test_knots;

namespace {
Trivariate sample_trivariate(bool rational) {
  std::mt19937 rng(77);
  std::uniform_real_distribution<double> U(-1.0, 1.0), W(0.5, 2.0);
  const std::array<KnotVector, 3> knots{test_knots(3, 1), test_knots(4, 2), test_knots(2, 3, 0, 1, 2)};
  int n = 1;
  for (const auto& k : knots) n *= k.size();
  std::vector<double> pts(static_cast<std::size_t>(n * 4)), w;
  for (double& p : pts) p = U(rng);
  if (rational) {
    w.resize(static_cast<std::size_t>(n));
    for (double& x : w) x = W(rng);
  }
  return Trivariate(knots, 4, pts, w);
}
}  // namespace

TEST_CASE("iso-surfaces and iso-curves equal the trivariate on them") {
  for (bool rational : {false, true}) {
    const Trivariate s = sample_trivariate(rational);
    for (int d = 0; d < 3; ++d) {
      const Surface iso_s = iso(s, d, 0.3);
      double worst = 0;
      for (const auto& t : random_params(iso_s, 100, 4)) {
        std::array<double, 3> full{};
        for (int e = 0, k = 0; e < 3; ++e) full[static_cast<std::size_t>(e)] = (e == d) ? 0.3 : t[static_cast<std::size_t>(k++)];
        const auto a = iso_s.eval(t), b = s.eval(full);
        for (int h = 0; h < 4; ++h) worst = std::max(worst, std::abs(a[static_cast<std::size_t>(h)] - b[static_cast<std::size_t>(h)]));
      }
      CHECK(worst < 1e-13);
      const Curve c = iso_curve(s, d, {0.2, 0.5, 0.8});
      for (double t : {0.0, 0.25, 0.7, 1.0}) {
        std::array<double, 3> full{0.2, 0.5, 0.8};
        full[static_cast<std::size_t>(d)] = t;
        const auto a = c.eval({t}), b = s.eval(full);
        for (int h = 0; h < 4; ++h) CHECK(std::abs(a[static_cast<std::size_t>(h)] - b[static_cast<std::size_t>(h)]) < 1e-13);
      }
    }
  }
  CHECK_THROWS_WITH(iso(sample_trivariate(false), 1, 1.5), Catch::Contains("outside the domain"));
}

TEST_CASE("the six boundary faces are the trivariate at its domain's ends") {
  const Trivariate s = sample_trivariate(true);
  for (Face f : all_faces) {
    const Surface face = boundary_face(s, f);
    const int dir = static_cast<int>(f) / 2;
    const double fixed = s.domain(dir)[static_cast<std::size_t>(static_cast<int>(f) % 2)];
    for (const auto& t : random_params(face, 50, 5)) {
      std::array<double, 3> full{};
      for (int e = 0, k = 0; e < 3; ++e) full[static_cast<std::size_t>(e)] = (e == dir) ? fixed : t[static_cast<std::size_t>(k++)];
      const auto a = face.eval(t), b = s.eval(full);
      for (int h = 0; h < 4; ++h) CHECK(std::abs(a[static_cast<std::size_t>(h)] - b[static_cast<std::size_t>(h)]) < 1e-13);
    }
    CHECK(face_from_name(face_name(f)) == f);
  }
  CHECK_THROWS_WITH(face_from_name("x1"), Catch::Contains("expected one of u0 u1 v0 v1 w0 w1"));
}

TEST_CASE("bounding boxes contain the spline and are exact for a box") {
  const Trivariate s = sample_trivariate(false);
  const auto box = bounding_box(s, 3);
  const auto net = s.control_box();
  for (int h = 0; h < 3; ++h) {
    CHECK(box[0][static_cast<std::size_t>(h)] >= net[0][static_cast<std::size_t>(h)]);
    CHECK(box[1][static_cast<std::size_t>(h)] <= net[1][static_cast<std::size_t>(h)]);
  }
  for (const auto& t : random_params(s, 500, 6)) {
    const auto p = s.eval(t);
    for (int h = 0; h < 3; ++h) {
      CHECK(p[static_cast<std::size_t>(h)] >= box[0][static_cast<std::size_t>(h)] - 1e-14);
      CHECK(p[static_cast<std::size_t>(h)] <= box[1][static_cast<std::size_t>(h)] + 1e-14);
    }
  }
  // The corners of a box are its control points' extremes.
  const KnotVector lin = KnotVector::bezier(2);
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) pts.insert(pts.end(), {-1.0 + 3 * i, 2.0 * j, 4.0 + k});
  const auto b = bounding_box(Trivariate({lin, lin, lin}, 3, pts));
  CHECK(b[0] == std::vector<double>{-1, 0, 4});
  CHECK(b[1] == std::vector<double>{2, 2, 5});
}

TEST_CASE("bounding boxes are the boxes of the Bezier pieces' control points, of the first coordinates") {
  // The box is read from the Bezier form's net and of the requested coordinates only: it must be
  // the box over bezier_pieces' control boxes (the definition), float for float.
  for (bool rational : {false, true}) {
    const Trivariate s = sample_trivariate(rational);
    std::array<std::vector<double>, 2> want{std::vector<double>(4, std::numeric_limits<double>::infinity()),
                                            std::vector<double>(4, -std::numeric_limits<double>::infinity())};
    const auto pieces = bezier_pieces(s);
    REQUIRE(pieces.size() > 1);
    for (const auto& p : pieces) {
      const auto b = p.control_box();
      for (std::size_t h = 0; h < 4; ++h) want[0][h] = std::min(want[0][h], b[0][h]), want[1][h] = std::max(want[1][h], b[1][h]);
    }
    for (int k : {1, 3, 4}) {
      const auto box = bounding_box(s, k);
      REQUIRE(box[0].size() == static_cast<std::size_t>(k));
      for (std::size_t h = 0; h < static_cast<std::size_t>(k); ++h) {
        CHECK(box[0][h] == want[0][h]);
        CHECK(box[1][h] == want[1][h]);
      }
    }
    CHECK(bounding_box(s)[0] == want[0]);
  }
}
