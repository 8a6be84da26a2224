// Property integrals of cells and Boolean pieces (slice/property_integrals.hpp). Truths: exact
// polynomial integrals over boxes. A box [lo, hi] as a cell quadratic in u whose properties are
// x^2, y and x z (their Bezier coefficients from the monomials' blossoms, so the properties are
// those functions exactly):
// - the plain cell: int x^2 = (hi^3 - lo^3)/3 x ..., and so on, to rounding;
// - minus a box through it: the box's integrals less those of the box common to both, to
//   rounding (planar faces cut along straight lines), right- and left-handed alike; the volume
//   the same sum gives (rho = 1) is piece_measures';
// - minus the one-cell Coons cylinder (boundary_fixtures.hpp): int x^2 over the hole is the
//   height times the cross-section's second moment, int int x^2 dA = oint x^3/3 dy on its four
//   cubic arcs (Green's theorem, Gauss on the arcs: exact), within the intersection curves'
//   accuracy;
// - refused with the reason: a trimmed piece of a non-affine trivariate (the cylinder less the
//   box).
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "trivox/geom/quadrature.hpp"
#include "trivox/slice/piece_measures.hpp"
#include "trivox/slice/property_integrals.hpp"
#include "trivox/vmodel/boolean.hpp"
#include "boundary_fixtures.hpp"

using namespace trivox;
using vmodel::BooleanOp;
using vmodel::VModel;

namespace {

/// The box [lo, hi], orders (3, 2, 2) (quadratic in u), with the properties x^2, y and x z
/// (the first `nprops` of them); `mirror` reverses u (det J < 0).
VModel graded_box(const std::string& name, std::array<double, 3> lo, std::array<double, 3> hi, int nprops = 3,
                  bool mirror = false) {
  std::vector<double> pts;
  const double a = lo[0], l = hi[0] - lo[0];
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i) {
        const int ii = mirror ? 2 - i : i;  // the Bezier index along x
        // x = a + l s on s in [0, 1]: Bezier coefficients of x (degree 2) a, a + l/2, a + l; of
        // x^2: a^2, a^2 + a l, (a + l)^2 (the blossom of x^2 at (0,0), (0,1), (1,1)).
        const double x = a + l * ii / 2.0;
        const double x2 = ii == 0 ? a * a : ii == 1 ? a * a + a * l : (a + l) * (a + l);
        const double y = j ? hi[1] : lo[1], z = k ? hi[2] : lo[2];
        const double props[3] = {x2, y, x * z};
        pts.insert(pts.end(), {x, y, z});
        pts.insert(pts.end(), props, props + nprops);
      }
  using spline::KnotVector;
  VModel m;
  const std::vector<std::string> names{"r", "g", "b"};
  m.properties.assign(names.begin(), names.begin() + nprops);
  m.cells.push_back({name, spline::Trivariate({KnotVector::bezier(3), KnotVector::bezier(2), KnotVector::bezier(2)}, 3 + nprops, pts)});
  return m;
}

/// int x^2, y, x z over the box [lo, hi].
std::array<double, 3> box_integrals(std::array<double, 3> lo, std::array<double, 3> hi) {
  const double lx = hi[0] - lo[0], ly = hi[1] - lo[1], lz = hi[2] - lo[2];
  const double ix2 = (hi[0] * hi[0] * hi[0] - lo[0] * lo[0] * lo[0]) / 3, ix = (hi[0] * hi[0] - lo[0] * lo[0]) / 2;
  const double iy = (hi[1] * hi[1] - lo[1] * lo[1]) / 2, iz = (hi[2] * hi[2] - lo[2] * lo[2]) / 2;
  return {ix2 * ly * lz, lx * iy * lz, ix * ly * iz};
}

/// int int x^2 dA over the region inside the four arcs: oint x^3 / 3 dy (degree 11 on a cubic
/// arc: 6 Gauss points are exact; 16 used).
double arcs_second_moment(double r) {
  const auto g = geom::gauss_legendre(16);
  double s2 = 0;
  for (int q = 0; q < 4; ++q) {
    const auto c = test::arc(r, test::kPi / 4 + q * test::kPi / 2, false);
    for (std::size_t n = 0; n < g.nodes.size(); ++n) {
      const double t = 0.5 * (1 + g.nodes[n]), w = 0.5 * g.weights[n], s = 1 - t;
      const double b[4] = {s * s * s, 3 * s * s * t, 3 * s * t * t, t * t * t};
      const double db[4] = {-3 * s * s, 3 * s * s - 6 * s * t, 6 * s * t - 3 * t * t, 3 * t * t};
      double x = 0, dy = 0;
      for (int i = 0; i < 4; ++i) x += b[i] * c[static_cast<std::size_t>(i)][0], dy += db[i] * c[static_cast<std::size_t>(i)][1];
      s2 += w * x * x * x / 3 * dy;
    }
  }
  return s2;
}

}  // namespace

TEST_CASE("property integrals of a plain cell", "[property_integrals]") {
  for (const bool mirror : {false, true}) {
    const std::array<double, 3> lo{0, 0, 0}, hi{2, 2, 1};
    const VModel A = graded_box("A", lo, hi, 3, mirror);
    const auto p = slice::property_integrals(A, 0);
    const auto want = box_integrals(lo, hi);  // 8/3 x 2, 4, 2
    REQUIRE(p.values.size() == 3);
    CHECK(p.method == "quadrature");
    CHECK(p.exact);
    for (std::size_t k = 0; k < 3; ++k) CHECK(std::abs(p.values[k] - want[k]) <= 1e-13 * std::abs(want[k]));
    CHECK(std::abs(p.volume - 4) <= 1e-13 * 4);
  }
}

TEST_CASE("property integrals of a box minus a box through it", "[property_integrals]") {
  // A = [0, 2]^2 x [0, 1] less B = [0.25, 0.75] x [0.5, 1.5] x [-1, 2]: A n B is the box
  // [0.25, 0.75] x [0.5, 1.5] x [0, 1].
  for (const bool mirror : {false, true}) {
    const std::array<double, 3> lo{0, 0, 0}, hi{2, 2, 1}, clo{0.25, 0.5, 0}, chi{0.75, 1.5, 1};
    const VModel A = graded_box("A", lo, hi, 3, mirror), B = graded_box("B", {0.25, 0.5, -1}, {0.75, 1.5, 2});
    const VModel D = vmodel::boolean(A, B, BooleanOp::subtraction);
    REQUIRE(D.cells.size() == 1);
    REQUIRE(!D.cells[0].plain());
    const auto p = slice::property_integrals(D, 0);
    INFO(p.note);
    REQUIRE(p.values.size() == 3);
    CHECK(p.method == "boundary");
    CHECK(p.exact);
    const auto whole = box_integrals(lo, hi), hole = box_integrals(clo, chi);
    for (std::size_t k = 0; k < 3; ++k) {
      const double want = whole[k] - hole[k];
      std::printf("box minus box%s: int %s dV = %.17g (expected %.17g)\n", mirror ? " (left-handed)" : "",
                  D.properties[k].c_str(), p.values[k], want);
      CHECK(std::abs(p.values[k] - want) <= 1e-12 * std::abs(whole[k]));
    }
    CHECK(std::abs(p.volume - 3.5) <= 1e-12 * 4);
    CHECK(std::abs(p.volume - slice::piece_measures(D, 0).volume) <= 1e-12 * 4);
  }
}

TEST_CASE("property integrals of a box minus a cylinder through it", "[property_integrals]") {
  // A = [-1, 1]^2 x [0, 1] with r = x^2 less the Coons cylinder of radius 0.5 (z in [-1, 2]):
  // int_A x^2 = 2/3 x 2 x 1, less 1 x the cross-section's second moment.
  const VModel A = graded_box("A", {-1, -1, 0}, {1, 1, 1}, 1), C = test::coons_cylinder(0.5, -1, 2);
  const VModel D = vmodel::boolean(A, C, BooleanOp::subtraction);
  REQUIRE(D.cells.size() == 1);
  const auto p = slice::property_integrals(D, 0);
  INFO(p.note);
  REQUIRE(p.values.size() == 1);
  const double s2 = arcs_second_moment(0.5), want = 4.0 / 3.0 - s2;
  REQUIRE(std::abs(s2 - test::kPi * std::pow(0.5, 4) / 4) < 1e-3);  // about the disc's pi r^4 / 4
  std::printf("box minus cylinder: int x^2 dV = %.17g (expected %.17g), volume %.17g\n", p.values[0], want, p.volume);
  CHECK(std::abs(p.values[0] - want) <= 1e-8 * (4.0 / 3.0));
  CHECK(std::abs(p.volume - slice::piece_measures(D, 0).volume) <= 1e-9 * 4);

  // The cylinder less the box: its trivariate is not affine, so nothing is claimed.
  const VModel E = vmodel::boolean(C, graded_box("A", {-1, -1, 0}, {1, 1, 1}, 1), BooleanOp::subtraction);
  REQUIRE(!E.cells.empty());
  const auto q = slice::property_integrals(E, 0);
  CHECK(q.values.empty());
  CHECK(q.note.find("not affine") != std::string::npos);
}
