// Representation changes leave the function unchanged: knot insertion and refinement, degree
// elevation, clamping, Bezier extraction, splitting, restriction, reparametrisation, reversal and
// swapping of directions (max deviation at many points below 1e-12 relative).
#include <catch2/catch.hpp>

#include <cmath>

#include "poly.hpp"
#include "trivox/error.hpp"
#include "trivox/spline/refine.hpp"

using namespace trivox::spline;
using trivox::test::random_params;
using trivox::test::TensorPoly;
using trivox::test::test_knots;

namespace {

/// A random (non-polynomial-in-disguise) trivariate: random control points, optional weights.
Trivariate random_trivariate(bool rational, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0), W(0.5, 2.0);
  const std::array<KnotVector, 3> knots{test_knots(4, seed + 1), test_knots(3, seed + 2), test_knots(2, seed + 3, 0, 1, 2)};
  int n = 1;
  for (const auto& k : knots) n *= k.size();
  std::vector<double> pts(static_cast<std::size_t>(n * 5)), w;
  for (double& p : pts) p = U(rng);
  if (rational) {
    w.resize(static_cast<std::size_t>(n));
    for (double& x : w) x = W(rng);
  }
  return Trivariate(knots, 5, std::move(pts), std::move(w));
}

/// max |a(map(t)) - b(t)| / (1 + |b|) over points t of b's domain.
template <int P, class Map>
double deviation(const TensorSpline<P>& a, const TensorSpline<P>& b, Map map, unsigned seed = 9) {
  double worst = 0;
  for (const auto& t : random_params(b, 400, seed)) {
    const auto x = a.eval(map(t));
    const auto y = b.eval(t);
    for (std::size_t h = 0; h < x.size(); ++h) worst = std::max(worst, std::abs(x[h] - y[h]) / (1 + std::abs(y[h])));
  }
  return worst;
}
const auto same = [](const auto& t) { return t; };

}  // namespace

TEST_CASE("knot insertion and refinement leave the function unchanged") {
  for (bool rational : {false, true}) {
    const Trivariate s = random_trivariate(rational, 100);
    for (int d = 0; d < 3; ++d) {
      const auto a = insert_knot(s, d, 0.37);
      CHECK(a.count(d) == s.count(d) + 1);
      CHECK(deviation(a, s, same) < 1e-12);
      const auto b = insert_knot(s, d, 0.61, s.knots(d).order() - 1);  // up to a C^0 knot
      CHECK(deviation(b, s, same) < 1e-12);
      const double many[] = {0.1, 0.1, 0.2, 0.55, 0.9, 0.999};
      const auto c = refine(s, d, many);
      CHECK(c.count(d) == s.count(d) + 6);
      CHECK(deviation(c, s, same) < 1e-12);
      CHECK(deviation(refine_uniform(s, d, 2), s, same) < 1e-12);
    }
  }
  const Trivariate s = random_trivariate(false, 101);
  CHECK_THROWS_WITH(insert_knot(s, 0, 1.5), Catch::Contains("outside the domain"));
  CHECK_THROWS_WITH(insert_knot(s, 1, 0.5, 4), Catch::Contains("multiplicity"));
  CHECK_THROWS_WITH(insert_knot(s, 3, 0.5), Catch::Contains("expected 0..2"));
}

TEST_CASE("degree elevation keeps the function and the continuity") {
  for (bool rational : {false, true}) {
    const Trivariate s = random_trivariate(rational, 200);
    for (int d = 0; d < 3; ++d)
      for (int by : {1, 2}) {
        const auto e = elevate(s, d, by);
        CHECK(e.knots(d).order() == s.knots(d).order() + by);
        for (const auto& b : s.knots(d).breakpoints())
          CHECK(e.knots(d).multiplicity(b.value) == b.multiplicity + by);
        INFO("direction " << d << " by " << by << (rational ? " rational" : ""));
        CHECK(deviation(e, s, same) < 1e-12);
      }
  }
  // A polynomial stays that polynomial, in the elevated space.
  const auto f = TensorPoly<1>::random({2}, 2, 3);
  const auto c = f.spline({test_knots(3, 4)});
  const auto e = elevate(c, 0, 3);
  double worst = 0;
  for (const auto& t : random_params(e, 200, 1))
    for (int h = 0; h < 2; ++h) worst = std::max(worst, std::abs(e.eval(t)[static_cast<std::size_t>(h)] - f.value(t, h)));
  CHECK(worst < 1e-13);
}

TEST_CASE("clamping an unclamped knot vector keeps the function on its domain") {
  std::vector<double> k;
  for (int i = 0; i < 10; ++i) k.push_back(i);
  const KnotVector kv(4, k);  // domain [3, 6]
  std::vector<double> pts;
  for (int i = 0; i < kv.size() * 2; ++i) pts.push_back(std::sin(1.3 * i));
  const Curve c({kv}, 2, pts);
  const Curve cl = clamp(c, 0);
  CHECK(cl.knots(0).clamped());
  CHECK(cl.domain(0) == c.domain(0));
  CHECK(deviation(cl, c, same) < 1e-12);
  // The clamped curve interpolates its end points.
  const auto e = c.eval({3.0});
  CHECK(std::abs(cl.point(0)[0] - e[0]) < 1e-14);
}

TEST_CASE("Bezier pieces tile the domain and equal the spline on each piece") {
  for (bool rational : {false, true}) {
    const Trivariate s = random_trivariate(rational, 300);
    const auto pieces = bezier_pieces(s);
    std::size_t expected = 1;
    for (int d = 0; d < 3; ++d) expected *= s.knots(d).breakpoints().size() - 1;
    REQUIRE(pieces.size() == expected);
    double worst = 0;
    for (const auto& p : pieces) {
      for (int d = 0; d < 3; ++d) {
        CHECK(p.count(d) == p.knots(d).order());
        CHECK(p.knots(d).clamped());
      }
      worst = std::max(worst, deviation(s, p, same, 2));
    }
    CHECK(worst < 1e-12);
  }
}

TEST_CASE("the Bezier form in every direction at once is the form direction by direction") {
  for (bool rational : {false, true}) {
    const Trivariate s = random_trivariate(rational, 310);
    Trivariate by_dir = s;
    for (int d = 0; d < 3; ++d) by_dir = to_bezier_form(by_dir, d);
    const Trivariate all = to_bezier_form(s);
    // The same knots, points and weights, bit for bit (the sums are the same, in the same order).
    for (int d = 0; d < 3; ++d) CHECK(all.knots(d).knots() == by_dir.knots(d).knots());
    REQUIRE(all.size() == by_dir.size());
    bool same_bits = all.weights() == by_dir.weights();
    for (int r = 0; r < all.size(); ++r)
      for (int h = 0; h < all.dim(); ++h) same_bits = same_bits && all.point(r)[h] == by_dir.point(r)[h];
    CHECK(same_bits);
    // And the function is unchanged: every knot at full multiplicity.
    CHECK(deviation(all, s, same) < 1e-12);
    for (int d = 0; d < 3; ++d)
      for (const auto& br : all.knots(d).breakpoints()) CHECK(br.multiplicity == all.knots(d).order());
  }
}

TEST_CASE("splitting and restriction give the function on the sub-domains") {
  for (bool rational : {false, true}) {
    const Trivariate s = random_trivariate(rational, 400);
    for (int d = 0; d < 3; ++d) {
      const auto [lo, hi] = split(s, d, 0.43);
      CHECK(lo.domain(d)[1] == 0.43);
      CHECK(hi.domain(d)[0] == 0.43);
      CHECK(deviation(s, lo, same) < 1e-12);
      CHECK(deviation(s, hi, same) < 1e-12);
      const auto r = restrict_to(s, d, 0.2, 0.7);
      CHECK(r.domain(d) == std::array<double, 2>{0.2, 0.7});
      CHECK(deviation(s, r, same) < 1e-12);
    }
  }
  const Trivariate s = random_trivariate(false, 401);
  CHECK_THROWS_WITH(split(s, 0, 0.0), Catch::Contains("strictly inside"));
  CHECK_THROWS_WITH(restrict_to(s, 1, 0.5, 0.4), Catch::Contains("expected front <= a < b <= back"));
}

TEST_CASE("reparametrisation, reversal and swapping map parameters as documented") {
  for (bool rational : {false, true}) {
    const Trivariate s = random_trivariate(rational, 500);
    for (int d = 0; d < 3; ++d) {
      const auto r = reparametrize(s, d, -2.0, 5.0);
      CHECK(r.domain(d) == std::array<double, 2>{-2.0, 5.0});
      CHECK(deviation(s, r, [d](auto t) { t[static_cast<std::size_t>(d)] = (t[static_cast<std::size_t>(d)] + 2.0) / 7.0; return t; }) < 1e-12);
      const auto v = reverse(s, d);
      CHECK(deviation(s, v, [d](auto t) { t[static_cast<std::size_t>(d)] = 1.0 - t[static_cast<std::size_t>(d)]; return t; }) < 1e-12);
      const auto vv = reverse(v, d);
      CHECK(std::equal(vv.points().begin(), vv.points().end(), s.points().begin()));
      CHECK(vv.weights() == s.weights());
    }
    const auto w = swap_directions(s, 0, 2);
    CHECK(w.orders() == std::array<int, 3>{s.knots(2).order(), s.knots(1).order(), s.knots(0).order()});
    CHECK(deviation(s, w, [](auto t) { return std::array<double, 3>{t[2], t[1], t[0]}; }) < 1e-15);
    CHECK(swap_directions(w, 0, 2) == s);
  }
}

TEST_CASE("make_compatible brings two splines into one space without changing them") {
  const Trivariate a = random_trivariate(false, 600);
  const auto f = TensorPoly<3>::random({1, 2, 2}, 5, 601);
  const Trivariate b = f.spline({test_knots(2, 602), test_knots(3, 603), test_knots(3, 604)});
  const auto [x, y] = make_compatible(a, b);
  CHECK(x.knot_vectors() == y.knot_vectors());
  CHECK(deviation(x, a, same) < 1e-12);
  CHECK(deviation(y, b, same) < 1e-12);
}

TEST_CASE("knot insertion into thousands of spans and into order 1 leaves the function unchanged") {
  // u: order 4 with 1500 uniform spans (as the fitted fillets' rails); v: order 1 (piecewise
  // constant, 3 spans), where Boehm's rule degenerates to duplicating a coefficient.
  std::vector<double> ku = {0, 0, 0, 0};
  for (int i = 1; i < 1500; ++i) ku.push_back(i / 1500.0);
  ku.insert(ku.end(), {1, 1, 1, 1});
  const std::array<KnotVector, 2> knots{KnotVector(4, ku), KnotVector(1, {0.0, 0.25, 0.5, 1.0})};
  const int n = knots[0].size() * knots[1].size();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::vector<double> pts(static_cast<std::size_t>(n * 2));
  for (double& p : pts) p = U(rng);
  const Surface s(knots, 2, std::move(pts));
  // Every interior knot raised to full multiplicity, then the pieces: 1500 x 3 of them.
  const auto pieces = bezier_pieces(s);
  REQUIRE(pieces.size() == 1500u * 3u);
  for (std::size_t k : {std::size_t{0}, std::size_t{777}, pieces.size() - 1}) {
    const auto& b = pieces[k];
    const double u = 0.3 * b.domain(0)[0] + 0.7 * b.domain(0)[1], v = 0.5 * (b.domain(1)[0] + b.domain(1)[1]);
    const auto x = b.eval({u, v}), y = s.eval({u, v});
    CHECK(std::abs(x[0] - y[0]) < 1e-12);
    CHECK(std::abs(x[1] - y[1]) < 1e-12);
  }
  // Many knots at once, unsorted, repeated, next to the domain's ends and on existing knots.
  const double many[] = {0.9995, 0.0001, 0.5, 0.5, 1.0 - 1e-9, 2.0 / 1500.0, 0.123456};
  const auto r = refine(s, 0, many);
  CHECK(r.count(0) == s.count(0) + 7);
  CHECK(deviation(r, s, same) < 1e-12);
  const auto c = insert_knot(s, 1, 0.75);
  CHECK(c.count(1) == s.count(1) + 1);
  CHECK(deviation(c, s, same) < 1e-12);
  CHECK_THROWS_WITH(insert_knot(s, 1, 0.25), Catch::Contains("multiplicity"));
}
