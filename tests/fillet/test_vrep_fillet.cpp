// The V-rep fillet (Masalha et al. 2021, Sec. 5, Def. 5.1, Lemma 2, Alg. 6): the half volumetric
// Boolean sum of S^_1 and S^_2 trimmed by S_b (the solid beyond it) and by its own faces S^_1, S^_2
// and caps. Expected values from the mathematics: in the right-angled corner T_hbs is the box
// spanned by the legs (Def. 5.1 of two perpendicular planar strips), its det J the product of
// the edge lengths; the trimmed volume is the region between the legs and the Hermite section
// (Green's theorem), the ruled fillet's; a point is in the trimmed cell exactly when it is in one
// of the ruled halves (the same region, bounded by the same S^_1, S^_2, S_b); the caps' trimming
// curves are S_b's end sections in the caps' affine parameters.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "corner.hpp"
#include "trivox/error.hpp"
#include "trivox/fillet/blend_surface.hpp"
#include "trivox/fillet/fillet.hpp"
#include "trivox/fillet/ruled_fillet.hpp"
#include "trivox/fillet/vrep_fillet.hpp"
#include "trivox/geom/closest_point.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/slice/locator.hpp"
#include "trivox/slice/trim.hpp"
#include "trivox/spline/calculus.hpp"
#include "trivox/spline/extract.hpp"

using namespace trivox;
using fillet_test::box_cell;
using fillet_test::Corner;
using spline::Face;
using spline::Surface;
using spline::Trivariate;

namespace {

vmodel::VModel model_of(std::vector<vmodel::VCell> cells) {
  vmodel::VModel m;
  m.properties = {"p"};
  m.cells = std::move(cells);
  return m;
}

}  // namespace

TEST_CASE("V-rep fillet of the corner: T_hbs is the legs' box, trimmed to the ruled fillet's region", "[fillet][vrep]") {
  const Corner c;  // d1 = 1 on the floor z = 0, d2 = 0.5 on the wall x = 2; C: x = 2, z = 0, y = 4t
  const Surface s1 = c.sub1(), s2 = c.sub2();
  fillet::BlendOptions bo;
  bo.tau = 1.2;
  const Surface b = fillet::blending_surface(c.input(s1, s2), bo);
  fillet::VrepReport rep;
  const fillet::VrepFillet v = fillet::vrep_fillet(s1, s2, b, {}, &rep);
  const auto halves = fillet::ruled_fillet(s1, s2, b);

  // Def. 5.1: T_hbs(u, v, w) = (2 + d1 v, 4u', d2 w) (u' = u or 1 - u), det J = 4 d1 d2 on
  // [0, 1]^3, so |T_hbs| = 4 d1 d2.
  const Trivariate& T = v.hbs;
  double affine = 0.0, det_lo = 1e300, det_hi = -1e300;
  for (int i = 0; i <= 8; ++i)
    for (int j = 0; j <= 8; ++j)
      for (int l = 0; l <= 8; ++l) {
        const double u = i / 8.0, vv = j / 8.0, w = l / 8.0;
        const auto x = T.eval({u, vv, w});
        const double y = rep.reversed ? 4 * (1 - u) : 4 * u;
        affine = std::max({affine, std::abs(x[0] - (2 + c.d1 * vv)), std::abs(x[1] - y), std::abs(x[2] - c.d2 * w)});
        const auto d = T.eval_derivatives({u, vv, w}, 1);
        const double det = d[4] * (d[9] * d[14] - d[10] * d[13]) - d[5] * (d[8] * d[14] - d[10] * d[12]) +
                           d[6] * (d[8] * d[13] - d[9] * d[12]);
        det_lo = std::min(det_lo, det);
        det_hi = std::max(det_hi, det);
      }
  const double ruled = geom::volume(halves[0]) + geom::volume(halves[1]);
  const double exact = fillet_test::hermite_area(c.d1, c.d2, bo.tau) * 4.0;
  const double trimmed = rep.hbs_volume - rep.beyond_volume[0] - rep.beyond_volume[1];
  std::printf("[vrep] corner: T_hbs affine to %.3g, det J [%.15g, %.15g] (4 d1 d2 = %g), |T_hbs| %.15g, beyond %.12g "
              "+ %.12g, trimmed %.15g, ruled %.15g, Green %.15g; v_b %.9g, S_b outside %.3g, cap gap %.3g, "
              "beyond det J [%.4g, %.4g] [%.4g, %.4g]\n",
              affine, det_lo, det_hi, 4 * c.d1 * c.d2, rep.hbs_volume, rep.beyond_volume[0], rep.beyond_volume[1],
              trimmed, ruled, exact, rep.v_b, rep.outside, rep.cap_gap, rep.beyond_jacobian[0][0],
              rep.beyond_jacobian[0][1], rep.beyond_jacobian[1][0], rep.beyond_jacobian[1][1]);
  CHECK(affine < 1e-13);
  CHECK(det_lo == Approx(4 * c.d1 * c.d2).epsilon(1e-13));
  CHECK(det_hi == Approx(4 * c.d1 * c.d2).epsilon(1e-13));
  CHECK(rep.hbs_volume == Approx(c.d1 * c.d2 * 4.0).epsilon(1e-13));  // the box d1 x d2 x 4
  CHECK(trimmed == Approx(exact).epsilon(1e-12));
  CHECK(trimmed == Approx(ruled).epsilon(1e-12));
  CHECK(rep.outside < 1e-12);  // the section stays in the legs' rectangle
  for (const auto& r : rep.beyond_jacobian) CHECK(r[0] * r[1] > 0.0);
  // Lemma 2: the faces are S^_1 and S^_2 (xyz; the properties too, except next to C, below).
  CHECK(!rep.closed);
  CHECK(rep.property_jump == Approx(10.0));  // floor 10, wall 20 on C

  // Membership: inside the trimmed V-cell iff inside a ruled half, at a grid over T_hbs's box
  // (y in (0, 4), x - 2 in (0, d1), z in (0, d2)), away from S_b (within 1e-6 the answer may
  // go either way).
  const slice::Locator ruled_loc(model_of({vmodel::VCell("a", halves[0]), vmodel::VCell("b", halves[1])}),
                                 {.tolerance = 1e-10});
  const vmodel::VModel vm = model_of({v.cell("fillet.1")});
  const slice::Locator vrep_loc(vm, {.tolerance = 1e-10});
  const geom::SurfaceDistance to_blend(spline::coordinates(b, 0, 3));
  int inside = 0, outside = 0, skipped = 0, disagree = 0;
  constexpr int n = 24;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int l = 0; l < 5; ++l) {
        const slice::Vec3 p{2 + c.d1 * (i + 0.5) / n, 0.3 + 0.85 * l, c.d2 * (j + 0.5) / n};
        if (to_blend.closest(p).distance < 1e-6) {
          ++skipped;
          continue;
        }
        const bool in_ruled = ruled_loc.locate(p).inside, in_vrep = vrep_loc.locate(p).inside;
        disagree += in_ruled != in_vrep;
        (in_vrep ? inside : outside) += 1;
      }
  std::printf("[vrep] corner membership: %d inside, %d beyond S_b, %d near S_b skipped, %d disagree with the ruled "
              "halves\n",
              inside, outside, skipped, disagree);
  CHECK(disagree == 0);
  CHECK(inside > 100);
  CHECK(outside > 100);
  // The trimmed volume the slicer's quadrature sees (slice::trimmed_volume, error about S_b's
  // area times a sub-box: 4 x 1.2 x 1/32 here) agrees with the exact one.
  const double quad = slice::trimmed_volume(vrep_loc, 0, 32);
  std::printf("[vrep] trimmed_volume (32^3 boxes) %.9g, exact %.9g\n", quad, exact);
  CHECK(std::abs(quad - exact) < 4.0 * 1.2 * c.d1 / 32);

  // Alg. 6 lines 8-11: on the caps y = 0 and y = 4 the trimming curve is the section in the
  // cap's parameters: (v, w) = ((x - 2) / d1, z / d2) of S_b(u_end, s).
  REQUIRE(v.caps.size() == 2);
  CHECK(rep.cap_gap < 1e-12);
  double curve_err = 0.0;
  for (const auto& cap : v.caps) {
    REQUIRE(cap.curves.size() == 1);
    const double y_end = (cap.face == Face::u0) != rep.reversed ? 0.0 : 4.0;
    const double u_b = y_end / 4.0;  // S_b keeps y = 4u
    for (int i = 0; i <= 20; ++i) {
      const double s = i / 20.0;
      const auto vw = cap.curves[0].eval({s});
      const auto x = b.eval({u_b, s});
      curve_err = std::max({curve_err, std::abs(vw[0] - (x[0] - 2) / c.d1), std::abs(vw[1] - x[2] / c.d2)});
    }
  }
  std::printf("[vrep] cap trimming curves: within %.3g of the sections\n", curve_err);
  CHECK(curve_err < 1e-6);  // a cubic interpolant of 65 samples of the cubic section
}

TEST_CASE("V-rep fillet refuses boundaries apart and bad options", "[fillet][vrep]") {
  const Corner c;
  const Surface s1 = c.sub1(), s2 = c.sub2();
  const Surface b = fillet::blending_surface(c.input(s1, s2), {});
  CHECK_THROWS_WITH(fillet::vrep_fillet(s1, s2, b, {.tolerance = 0.0}), Catch::Contains("tolerance 0"));
  // S^_2 moved off C by 0.01: the copies of C are apart.
  Surface moved = s2;
  for (int i = 0; i < moved.size(); ++i) moved.point(i)[2] += 0.01;
  CHECK_THROWS_WITH(fillet::vrep_fillet(s1, moved, b), Catch::Contains("expected the same curve C"));
}

TEST_CASE("fillet_faces with construction vrep: one trimmed cell and its quality report", "[fillet][vrep]") {
  // Floor [0,4]^2 x [-1,0] (property 10), wall [1,2] x [-0.5,4.5] x [-0.5,3] (property 20):
  // C is x = 2, z = 0 for y in [0, 4]; d1 = 1, d2 = 0.5; Hermite tau 1.2.
  const Trivariate floor = box_cell({0, 0, -1}, {4, 4, 0}, 10.0), wall = box_cell({1, -0.5, -0.5}, {2, 4.5, 3}, 20.0);
  const double d1 = 1.0, d2 = 0.5, tau = 1.2, length = 4.0;
  fillet::FilletOptions o;
  o.distance = {d1, d2};
  o.blend.tau = tau;
  o.construction = fillet::Construction::vrep;
  const auto fillets = fillet::fillet_faces(floor, Face::w1, wall, Face::u1, o);
  REQUIRE(fillets.size() == 1);
  const auto& f = fillets[0];
  const auto& q = f.quality;
  REQUIRE(f.cells.size() == 1);
  REQUIRE(f.beyond.size() == 2);
  REQUIRE(q.cell_volume.size() == 1);
  const double exact = fillet_test::hermite_area(d1, d2, tau) * length;
  std::printf("[vrep] fillet_faces: volume %.15g (Green %.15g), gap %.3g %.3g, S_b gap %.3g, G1 %.3g %.3g, glue %.3g, "
              "det J [%.15g, %.15g], property jump %.3g %.3g, %.3f s\n",
              q.cell_volume[0], exact, q.gap[0], q.gap[1], q.blend_gap, q.g1_angle[0], q.g1_angle[1], q.glue, q.det_min,
              q.det_max, q.property_jump[0], q.property_jump[1], q.seconds);
  CHECK(q.construction == fillet::Construction::vrep);
  CHECK(q.cell_volume[0] == Approx(exact).epsilon(1e-11));
  CHECK(q.gap[0] < 1e-12);
  CHECK(q.gap[1] < 1e-12);
  CHECK(q.blend_gap < 1e-12);
  CHECK(q.g1_angle[0] < 1e-6);
  CHECK(q.g1_angle[1] < 1e-6);
  CHECK(q.glue < 1e-14);  // W_1 and W_2 share Rld(C_b, K)
  CHECK(q.jacobian() == "positive");
  // T_hbs of perpendicular strips: det J = d1 d2 |C'| with |C'| = 4 everywhere.
  CHECK(q.det_min == Approx(4 * d1 * d2).epsilon(1e-12));
  CHECK(q.det_max == Approx(4 * d1 * d2).epsilon(1e-12));
  // Eq. 8's jump 20 - 10 on C: C carries the mean, so the faces deviate by half of it there.
  CHECK(q.vrep.property_jump == Approx(10.0));
  CHECK(std::max(q.property_jump[0], q.property_jump[1]) == Approx(5.0).margin(1e-12));
  CHECK(!q.vrep.closed);
  CHECK(f.caps.size() == 2);

  // The model cell: trimmed (VCell::without), named as asked, the trimming solid named after it.
  const vmodel::VCell cell = f.vcell(0, "fillet.1");
  CHECK(!cell.plain());
  REQUIRE(cell.without.size() == 1);
  REQUIRE(cell.without[0].size() == 2);
  CHECK(cell.without[0][0].name == "fillet.1.beyond.1");
  CHECK(cell.without[0][1].name == "fillet.1.beyond.2");
  CHECK(cell.trim_curves.size() == 2);
}
