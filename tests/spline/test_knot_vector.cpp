// Knot vectors: validation, span search, and the basis functions' partition of unity.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>

#include "poly.hpp"
#include "trivox/error.hpp"
#include "trivox/spline/knot_vector.hpp"

using trivox::Error;
using trivox::spline::KnotVector;

namespace {
std::string message_of(int order, std::vector<double> k) {
  try {
    KnotVector kv(order, std::move(k));
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST_CASE("knot vectors reject malformed input with a message saying what was expected") {
  CHECK_THAT(message_of(0, {0, 1}), Catch::Contains("expected an order"));
  CHECK_THAT(message_of(3, {0, 0, 0, 1, 1}), Catch::Contains("expected at least 6"));
  CHECK_THAT(message_of(2, {0, 0, 1, 0.5, 1, 1}), Catch::Contains("non-decreasing"));
  CHECK_THAT(message_of(2, {0, 0, std::nan(""), 1, 1}), Catch::Contains("finite"));
  CHECK_THAT(message_of(2, {0, 0, std::numeric_limits<double>::infinity(), 1, 1}), Catch::Contains("finite"));
  CHECK_THAT(message_of(2, {0, 0, 0.5, 0.5, 0.5, 1, 1}), Catch::Contains("multiplicity <= order"));
  CHECK_THAT(message_of(2, {0, 0, 0, 0}), Catch::Contains("empty domain"));
  CHECK(message_of(3, {0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1}).empty());  // C^-1 interior knot is fine
}

TEST_CASE("find_span returns the half-open span, the last non-empty one at the end") {
  const KnotVector kv(3, {0, 0, 0, 0.25, 0.5, 0.5, 1, 1, 1});
  CHECK(kv.size() == 6);
  CHECK(kv.find_span(0.0) == 2);
  CHECK(kv.find_span(0.1) == 2);
  CHECK(kv.find_span(0.25) == 3);
  CHECK(kv.find_span(0.49) == 3);
  CHECK(kv.find_span(0.5) == 5);
  CHECK(kv.find_span(1.0) == 5);
  CHECK(kv.find_span(-3.0) == 2);  // clamped to the domain
  CHECK(kv.find_span(0.6, 5) == 5);
  CHECK(kv.find_span(0.3, 5) == 3);  // a wrong hint is ignored
}

TEST_CASE("basis functions sum to one and their derivatives to zero") {
  std::mt19937 rng(1);
  for (int order = 1; order <= 6; ++order) {
    const KnotVector kvs[] = {trivox::test::test_knots(order, 10u + static_cast<unsigned>(order), -1.0, 2.0),
                              KnotVector::uniform(order, 5),
                              // unclamped: uniform knots beyond the domain
                              KnotVector(order, [&] {
                                std::vector<double> k;
                                for (int i = 0; i < 2 * order + 3; ++i) k.push_back(i * 0.5);
                                return k;
                              }())};
    for (const auto& kv : kvs) {
      std::uniform_real_distribution<double> U(kv.front(), kv.back());
      for (int rep = 0; rep < 200; ++rep) {
        const double t = rep == 0 ? kv.front() : rep == 1 ? kv.back() : U(rng);
        const int mu = kv.find_span(t);
        std::vector<double> N(static_cast<std::size_t>(3 * order));
        kv.basis_derivatives(mu, t, 2, N.data());
        double s0 = 0, s1 = 0, s2 = 0;
        for (int j = 0; j < order; ++j) {
          CHECK(N[static_cast<std::size_t>(j)] >= -1e-15);
          s0 += N[static_cast<std::size_t>(j)];
          s1 += N[static_cast<std::size_t>(order + j)];
          s2 += N[static_cast<std::size_t>(2 * order + j)];
        }
        CHECK(std::abs(s0 - 1.0) < 1e-14);
        CHECK(std::abs(s1) < 1e-11);
        CHECK(std::abs(s2) < 1e-9);
        std::vector<double> B(static_cast<std::size_t>(order));
        kv.basis(mu, t, B.data());
        for (int j = 0; j < order; ++j) CHECK(std::abs(B[static_cast<std::size_t>(j)] - N[static_cast<std::size_t>(j)]) < 1e-15);
      }
    }
  }
}

TEST_CASE("breakpoints, multiplicities and Greville abscissae") {
  const KnotVector kv(3, {0, 0, 0, 0.25, 0.5, 0.5, 1, 1, 1});
  const auto br = kv.breakpoints();
  REQUIRE(br.size() == 4);
  CHECK(br[2].value == 0.5);
  CHECK(br[2].multiplicity == 2);
  CHECK(kv.multiplicity(0.5) == 2);
  CHECK(kv.multiplicity(0.3) == 0);
  CHECK(kv.clamped());
  const auto g = kv.greville();
  // Greville abscissae reproduce the identity: sum_i g_i N_i(t) = t (degree >= 1).
  for (double t : {0.0, 0.1, 0.3, 0.5, 0.77, 1.0}) {
    std::vector<double> N(3);
    const int mu = kv.find_span(t);
    kv.basis(mu, t, N.data());
    double s = 0;
    for (int j = 0; j < 3; ++j) s += g[static_cast<std::size_t>(mu - 2 + j)] * N[static_cast<std::size_t>(j)];
    CHECK(std::abs(s - t) < 1e-15);
  }
}
