// Boundary meshes of Boolean results from their trimmed faces (slice/trimmed_mesh.hpp). Truths:
// - topology: a closed orientable surface has every edge in exactly two triangles, in opposite
//   directions, and V - E + F = 2 (1 - g) per shell of genus g: a box with a notch cut out of it
//   (genus 0) gives 2, a box with a hole through it (a bar or a cylinder, genus 1) gives 0, a box
//   with a cavity is two shells (the box and the cavity's wall) of genus 0, so 4;
// - volumes: a closed, outward-oriented triangle mesh encloses the volume of the divergence
//   theorem, positive; it approximates the solid within about the chordal tolerance times the
//   area, so within 1e-3 relative at the fine tolerance used here, of the pieces' exact volumes
//   on the same faces (slice::piece_measures) and of the analytic volumes: boxes' products, and
//   4 - A_c for the box minus the Coons cylinder (A_c by Green's theorem on its four arcs,
//   boundary_fixtures.hpp);
// - union of two boxes in a row with no common plane: one shell of genus 0, volume
//   2 + 8 - 1 = 9 and area 28 (B's 24 less the unit square where A enters, plus A's five faces
//   outside B), also after slice::untrim (as `trivox build` leaves it); per cell, the three
//   pieces (A n B, A - B, B - A) are three shells;
// - box union cylinder through it: one solid of genus 0, volume 4 + 2 A_c; per cell, the
//   cylinder's part outside the box is one cell of two separate pieces: 4 shells, the box with
//   the hole of genus 1 and three of genus 0, V - E + F = 0 + 3 x 2;
// - a ball (construct's 7 bicubic cells) less a box through it: one solid of genus 0, its
//   volume within 1e-3 of the pieces' exact one, which is the cap's pi h^2 (3r - h) / 3 within
//   the primitive's distance from the true sphere.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <string>

#include "trivox/construct/primitives.hpp"
#include "trivox/error.hpp"
#include "trivox/slice/piece_measures.hpp"
#include "trivox/slice/trim.hpp"
#include "trivox/slice/trimmed_mesh.hpp"
#include "trivox/vmodel/boolean.hpp"
#include "boundary_fixtures.hpp"

using namespace trivox;
using test::box;
using test::coons_cylinder;
using vmodel::BooleanOp;
using vmodel::VModel;

namespace {

/// The sum of the pieces' exact volumes.
double pieces_volume(const VModel& m) {
  double v = 0;
  for (int c = 0; c < static_cast<int>(m.cells.size()); ++c) v += slice::piece_measures(m, c).volume;
  return v;
}

struct Figures {
  vmodel::BoundaryMesh mesh;
  vmodel::EdgeReport edges;
  int shells = 0;
  std::int64_t euler = 0;
  double volume = 0, area = 0;
};

Figures mesh_of(const VModel& m, double tolerance, bool per_cell = false) {
  slice::TrimmedMeshOptions o;
  o.mesh.tolerance = tolerance;
  o.mesh.per_cell = per_cell;
  Figures f;
  f.mesh = slice::mesh_trimmed_boundary(m, o);
  f.edges = vmodel::edge_report(f.mesh);
  f.shells = vmodel::shell_count(f.mesh);
  f.euler = vmodel::euler_characteristic(f.mesh);
  f.volume = vmodel::enclosed_volume(f.mesh);
  f.area = vmodel::surface_area(f.mesh);
  return f;
}

void print(const char* what, const Figures& f, double truth) {
  std::printf("%s: %zu triangles, %zu vertices, %d dropped, boundary edges %lld, non-manifold %lld, shells %d, euler %lld, "
              "volume %.12g (pieces %.12g, truth %.12g), max deviation %.3g (tolerance %.3g)\n",
              what, f.mesh.triangles.size(), f.mesh.vertices.size(), f.mesh.dropped_triangles,
              static_cast<long long>(f.edges.boundary_edges), static_cast<long long>(f.edges.non_manifold_edges),
              f.shells, static_cast<long long>(f.euler), f.volume, f.mesh.cell_volume, truth, f.mesh.max_deviation,
              f.mesh.tolerance);
}

void check_solid(const Figures& f, int shells, std::int64_t euler, double truth) {
  CHECK(f.edges.manifold());
  CHECK(f.shells == shells);
  CHECK(f.euler == euler);
  CHECK(f.volume > 0);
  CHECK(std::abs(f.volume - f.mesh.cell_volume) <= 1e-3 * f.mesh.cell_volume);
  CHECK(std::abs(f.volume - truth) <= 1e-3 * truth);
  CHECK(std::abs(f.mesh.cell_volume - truth) <= 1e-8 * truth);
  CHECK(f.mesh.max_deviation <= f.mesh.tolerance);
}

}  // namespace

TEST_CASE("meshes of boxes minus boxes", "[trimmed_mesh]") {
  const VModel A = box("A", {0, 0, 0}, {2, 2, 1});
  // A notch: B takes [1.5, 2] x [0.5, 1.5] x [0.5, 1] out of A's edge: genus 0, 4 - 0.25.
  const VModel notch = vmodel::boolean(A, box("B", {1.5, 0.5, 0.5}, {2.5, 1.5, 2}), BooleanOp::subtraction);
  REQUIRE(slice::has_trimmed_cells(notch));
  const auto n = mesh_of(notch, 1e-3);
  print("box minus notch", n, 3.75);
  check_solid(n, 1, 2, 3.75);
  // Planar faces cut along straight lines: the mesh is exact.
  CHECK(std::abs(n.volume - 3.75) <= 1e-12 * 3.75);
  // Area: A's 16 less the notch's mouth on the top and on x = 2 (0.5 each), plus its floor, its
  // wall x = 1.5 (0.5 each) and its two ends (0.25 each).
  CHECK(std::abs(n.area - 16.5) <= 1e-12 * 16.5);
  // A bar through it: genus 1, 4 - 0.5.
  const VModel hole = vmodel::boolean(A, box("B", {0.25, 0.5, -1}, {0.75, 1.5, 2}), BooleanOp::subtraction);
  const auto h = mesh_of(hole, 1e-3);
  print("box minus bar", h, 3.5);
  check_solid(h, 1, 0, 3.5);
  CHECK(std::abs(h.volume - 3.5) <= 1e-12 * 3.5);
  CHECK(std::abs(h.area - 18) <= 1e-12 * 18);
  // The plain box alone (no trimmed cell) is meshed the same way: 6 faces.
  const auto plain = mesh_of(A, 1e-3);
  check_solid(plain, 1, 2, 4);
  CHECK(plain.mesh.faces == 6);
}

TEST_CASE("mesh of a box minus a cylinder through it", "[trimmed_mesh]") {
  const VModel A = box("A", {-1, -1, 0}, {1, 1, 1}), C = coons_cylinder(0.5, -1, 2);
  const double ac = test::arcs_area_length(0.5).first;
  const VModel D = vmodel::boolean(A, C, BooleanOp::subtraction);
  const auto f = mesh_of(D, 1e-4);
  print("box minus cylinder", f, 4 - ac);
  check_solid(f, 1, 0, 4 - ac);
  CHECK(std::abs(f.mesh.cell_volume - pieces_volume(D)) <= 1e-12 * 4);
  // The chords of the hole's wall lie inside the hole: the mesh holds a little more than the
  // solid, by less than the tolerance times the wall's area (the arcs' length times 1).
  CHECK(f.volume >= f.mesh.cell_volume - 1e-12);
  CHECK(f.volume - f.mesh.cell_volume <= 1e-4 * test::arcs_area_length(0.5).second);
  // A coarser tolerance: fewer triangles, still closed.
  const auto g = mesh_of(D, 1e-2);
  CHECK(g.edges.manifold());
  CHECK(g.euler == 0);
  CHECK(g.mesh.triangles.size() <= f.mesh.triangles.size());
  CHECK(std::abs(g.volume - g.mesh.cell_volume) <= 1e-2 * 3.2);
}

TEST_CASE("mesh of a box with a cylindrical cavity", "[trimmed_mesh]") {
  const VModel A = box("A", {-1, -1, 0}, {1, 1, 1}), C = coons_cylinder(0.5, 0.25, 0.75);
  const double ac = test::arcs_area_length(0.5).first;
  const auto f = mesh_of(vmodel::boolean(A, C, BooleanOp::subtraction), 1e-4);
  print("box with a cavity", f, 4 - 0.5 * ac);
  check_solid(f, 2, 4, 4 - 0.5 * ac);
}

TEST_CASE("meshes of unions", "[trimmed_mesh]") {
  // Two boxes in a row, no plane in common.
  const VModel A = box("A", {0, 0, 0}, {2, 1, 1}), B = box("B", {1, -0.5, -0.5}, {3, 1.5, 1.5});
  const VModel U = vmodel::boolean(A, B, BooleanOp::union_op);
  const auto u = mesh_of(U, 1e-3);
  print("two boxes united", u, 9);
  check_solid(u, 1, 2, 9);
  CHECK(std::abs(u.volume - 9) <= 1e-12 * 9);
  CHECK(std::abs(u.area - 28) <= 1e-12 * 28);
  // As `trivox build` leaves it: the pieces that are parameter boxes restricted to them, their
  // conditions kept (whole faces on the conditions' faces): the same solid.
  const auto r = mesh_of(slice::untrim(U), 1e-3);
  print("two boxes united, restricted", r, 9);
  check_solid(r, 1, 2, 9);
  // (untrim finds the boxes' faces by bisection to 1e-13 of the domain.)
  CHECK(std::abs(r.area - 28) <= 1e-9 * 28);
  const auto c = mesh_of(U, 1e-3, true);
  print("two boxes united, per cell", c, 9);
  check_solid(c, 3, 6, 9);

  // A box and a cylinder through it.
  const VModel Q = box("A", {-1, -1, 0}, {1, 1, 1}), C = coons_cylinder(0.5, -1, 2);
  const double ac = test::arcs_area_length(0.5).first;
  const VModel V = vmodel::boolean(Q, C, BooleanOp::union_op);
  const auto v = mesh_of(V, 1e-4);
  print("box union cylinder", v, 4 + 2 * ac);
  check_solid(v, 1, 2, 4 + 2 * ac);
  const auto w = mesh_of(V, 1e-4, true);
  print("box union cylinder, per cell", w, 4 + 2 * ac);
  check_solid(w, 4, 6, 4 + 2 * ac);
}

TEST_CASE("trimmed meshes refuse bad options", "[trimmed_mesh]") {
  const VModel A = box("A", {0, 0, 0}, {2, 2, 1});
  const VModel D = vmodel::boolean(A, box("B", {1.5, 0.5, 0.5}, {2.5, 1.5, 2}), BooleanOp::subtraction);
  slice::TrimmedMeshOptions o;
  o.mesh.tolerance = -1;
  CHECK_THROWS_AS(slice::mesh_trimmed_boundary(D, o), Error);
  o.mesh.tolerance = 1e-3;
  o.weld = 0.9;
  CHECK_THROWS_AS(slice::mesh_trimmed_boundary(D, o), Error);
  o.weld = 1e-2;
  o.mesh.max_triangles = 10;
  CHECK_THROWS_AS(slice::mesh_trimmed_boundary(D, o), Error);
  CHECK_THROWS_AS(slice::mesh_trimmed_boundary(VModel{}), Error);
}

TEST_CASE("mesh of a ball cut by a box", "[trimmed_mesh]") {
  // The unit ball of construct's 7 bicubic cells less the box x >= 0.3: one solid of genus 0.
  // Its faces are cut along marched curves, and next to the cut disc's extreme points the
  // untrimming leaves slabs narrower than the default weld distance.
  VModel S, B;
  for (auto& c : construct::build_primitive("S", construct::Sphere{{0, 0, 0}, 1})) S.cells.push_back({c.name, c.volume});
  for (auto& c : construct::build_primitive("B", construct::Box{{0.3, -2, -2}, {2, 2, 2}})) B.cells.push_back({c.name, c.volume});
  const VModel D = vmodel::boolean(S, B, BooleanOp::subtraction);
  const auto f = mesh_of(D, 5e-4);
  const double h = 1.3, cap = test::kPi * h * h * (3 - h) / 3;  // the exact ball's part x <= 0.3
  print("ball minus box", f, cap);
  CHECK(f.edges.manifold());
  CHECK(f.shells == 1);
  CHECK(f.euler == 2);
  CHECK(std::abs(f.volume - f.mesh.cell_volume) <= 1e-3 * f.mesh.cell_volume);
  CHECK(std::abs(f.volume - f.mesh.cell_volume) <= f.mesh.tolerance * f.area);
  // The primitive's cells lie within about 1e-3 of the true sphere.
  CHECK(std::abs(f.mesh.cell_volume - cap) <= 2e-3 * cap);
}
