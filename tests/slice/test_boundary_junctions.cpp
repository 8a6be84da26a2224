// Boundary faces of pieces cut by multi-cell primitives (slice/boundary_faces.hpp over
// geom::trim_face's arrangements with junctions). Truths, for the box A = [-1, 1]^2 x [0, 1]:
// - minus the 5-cell construct cylinder C of radius 0.5 about the z axis through it (z in
//   [-1, 2]): the box's top meets the five cells' lateral faces in a square, four radial
//   segments and four arcs meeting at T junctions; the top keeps 4 - A_c, the hole's wall is
//   L_c x 1 and the whole boundary is 2 (4 - A_c) + 8 + L_c, where A_c and L_c are the area and
//   perimeter of the cylinder's cross-section, computed from its four outer cells' lateral faces
//   (Green's theorem, 1/2 loop integral of x y' - y x', exact Gauss rule for the polynomial
//   integrand; the length with 64 Gauss points per span of a smooth integrand); the faces shared
//   by two of the cylinder's cells lie inside C and bound nothing;
// - minus the same cylinder wholly inside it (z in [0.25, 0.75], a cavity): 16 + 2 A_c + 0.5 L_c,
//   the lid and floor made of the five cells' end faces, and no shared face reported.
// The 7-cell ball and the 5-cell torus as conditions are measured in
// test_boolean_curved_measures.cpp (inclusion-exclusion).
// The holes are bounded by marched intersection curves, within their tolerance (1e-10) of the
// exact sections, so areas agree to about 1e-9, checked to 1e-8 relative.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "trivox/construct/primitives.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/geom/trimmed_surface.hpp"
#include "trivox/slice/boundary_faces.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/vmodel/boolean.hpp"
#include "boundary_fixtures.hpp"

using namespace trivox;
using vmodel::BooleanOp;
using vmodel::VModel;

namespace {

VModel unit_box() {
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) pts.insert(pts.end(), {i ? 1.0 : -1.0, j ? 1.0 : -1.0, k ? 1.0 : 0.0});
  const auto b = spline::KnotVector::bezier(2);
  VModel m;
  m.cells.push_back({"A", spline::Trivariate({b, b, b}, 3, pts)});
  return m;
}

VModel primitive(const construct::Primitive& p) {
  VModel m;
  for (auto& c : construct::build_primitive("p", p)) m.cells.push_back({c.name, std::move(c.volume)});
  return m;
}

/// Along the iso-curve of surface f at fixed parameter `fixed` in direction 1 - dir (running in
/// direction dir): 1/2 int (x y' - y x') (Green's theorem) and int |(x', y')|, with 64 Gauss points
/// per knot span; also the largest |z - z0| on the Gauss points.
struct Section {
  double area = 0, length = 0, z_off = 0;
};
void add_section(const spline::Surface& f, int dir, double fixed, double z0, Section& s) {
  const auto g = geom::gauss_legendre(64);
  const auto& kv = f.knots(dir).knots();
  for (std::size_t i = 0; i + 1 < kv.size(); ++i) {
    const double t0 = kv[i], t1 = kv[i + 1];
    if (!(t1 > t0)) continue;
    for (std::size_t q = 0; q < g.nodes.size(); ++q) {
      const double t = 0.5 * (t0 + t1) + 0.5 * (t1 - t0) * g.nodes[q], w = 0.5 * (t1 - t0) * g.weights[q];
      std::array<double, 2> uv{};
      uv[static_cast<std::size_t>(dir)] = t;
      uv[static_cast<std::size_t>(1 - dir)] = fixed;
      const auto d = f.eval_derivatives(uv, 1);  // value, d/du, d/dv; 3 coordinates each
      const std::size_t o = static_cast<std::size_t>(3 * (1 + dir));
      s.area += w * 0.5 * (d[0] * d[o + 1] - d[1] * d[o]);
      s.length += w * std::hypot(d[o], d[o + 1]);
      s.z_off = std::max(s.z_off, std::abs(d[2] - z0));
    }
  }
}

/// The cross-section of a construct cylinder along z at its middle height, z = 0.5 for both
/// cylinders here (z_off measures the distance from it), from its outer cells'
/// u1 faces (v counter-clockwise about z; the lateral faces are extrusions along z, so any height
/// serves).
Section cylinder_section(const VModel& C) {
  Section sec;
  for (const auto& c : C.cells) {
    if (c.name == "p.core") continue;
    const auto f = spline::boundary_face(c.volume, spline::Face::u1);
    const auto wd = f.domain(1);
    add_section(f, 0, 0.5 * (wd[0] + wd[1]), 0.5, sec);
  }
  return sec;
}

}  // namespace

TEST_CASE("boundary faces of a box minus the 5-cell cylinder through it", "[boundary_faces][junctions]") {
  const VModel A = unit_box();
  const VModel C = primitive(construct::Cylinder{{0, 0, -1}, {0, 0, 1}, 0.5, 3});
  REQUIRE(C.cells.size() == 5);
  const Section sec = cylinder_section(C);
  const double pi = std::acos(-1.0);
  REQUIRE(std::abs(sec.area - pi * 0.25) < 1e-3);
  REQUIRE(sec.z_off < 1e-12);
  const VModel D = vmodel::boolean(A, C, BooleanOp::subtraction);
  REQUIRE(D.cells.size() == 1);
  std::vector<slice::BoundaryFace> faces;
  const double d = test::cells_boundary_area(D, &faces);
  double top = 0, wall = 0;
  int walls = 0;
  for (const auto& f : faces) {
    if (f.source == -1 && f.face == spline::Face::w1) top += f.area;
    if (f.source >= 0) {
      wall += f.area, ++walls;
      // Only the outer cells' curved faces bound the hole; faces shared by two cells do not.
      CHECK(f.source_name != "p.core");
      CHECK(f.face == spline::Face::u1);
    }
  }
  const double expected = 2 * (4 - sec.area) + 8 + sec.length;
  std::printf("box minus 5-cell cylinder: %zu faces, top %.15g (4 - A_c = %.15g), wall %.15g in %d faces (L_c = %.15g), "
              "boundary %.15g (expected %.15g)\n",
              faces.size(), top, 4 - sec.area, wall, walls, sec.length, d, expected);
  CHECK(walls == 4);
  CHECK(std::abs(top - (4 - sec.area)) <= 1e-8 * 4);
  CHECK(std::abs(wall - sec.length) <= 1e-8 * sec.length);
  CHECK(std::abs(d - expected) <= 1e-8 * expected);
}

TEST_CASE("boundary faces of a box minus the 5-cell cylinder inside it", "[boundary_faces][junctions]") {
  // The cylinder z in [0.25, 0.75] is a cavity: the box keeps its 16, the cavity's lid and floor
  // are the five cells' w faces (2 A_c), its wall the outer cells' u1 faces (0.5 L_c); every
  // other face of the cells is shared by two of them and lies inside C.
  const VModel A = unit_box();
  const VModel C = primitive(construct::Cylinder{{0, 0, 0.25}, {0, 0, 1}, 0.5, 0.5});
  const Section sec = cylinder_section(C);
  REQUIRE(sec.z_off < 1e-12);
  const VModel D = vmodel::boolean(A, C, BooleanOp::subtraction);
  std::vector<slice::BoundaryFace> faces;
  const double d = test::cells_boundary_area(D, &faces);
  double own = 0, lids = 0, wall = 0;
  for (const auto& f : faces) {
    if (f.source == -1) own += f.area;
    else if (f.face == spline::Face::w0 || f.face == spline::Face::w1) lids += f.area;
    else if (f.face == spline::Face::u1 && f.source_name != "p.core") wall += f.area;
    else FAIL("a face shared by two cells is reported: " << f.source_name << " " << spline::face_name(f.face));
  }
  const double expected = 16 + 2 * sec.area + 0.5 * sec.length;
  std::printf("box minus 5-cell cylinder inside: %zu faces, own %.15g, lid and floor %.15g (2 A_c = %.15g), wall %.15g "
              "(0.5 L_c = %.15g), boundary %.15g (expected %.15g)\n",
              faces.size(), own, lids, 2 * sec.area, wall, 0.5 * sec.length, d, expected);
  CHECK(faces.size() == 6 + 10 + 4);
  CHECK(std::abs(own - 16) <= 1e-12 * 16);
  CHECK(std::abs(lids - 2 * sec.area) <= 1e-10 * lids);
  CHECK(std::abs(wall - 0.5 * sec.length) <= 1e-10 * wall);
  CHECK(std::abs(d - expected) <= 1e-10 * expected);
}

