// The boundary mesh of V-models (vmodel/boundary_mesh.hpp). Expected values come from
// mathematics: volumes and areas of boxes and prisms (planar faces: the mesh is exact), the
// counts of a box's faces (two triangles per boundary unit square), Euler's formula (V - E + F =
// 2 per closed shell of genus 0, 0 for a torus), analytic volumes of primitives, and the order of
// the error of piecewise linear interpolation (h^2 against a tolerance ~ h^2: linear in the
// tolerance).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "trivox/construct/primitives.hpp"
#include "trivox/error.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/vmodel/boundary_mesh.hpp"

using namespace trivox;
using namespace trivox::vmodel;
using spline::KnotVector;
using spline::Trivariate;

namespace {

/// The trilinear cell [lo, hi], one property equal to x; `flip_u` runs u from hi to lo (a
/// left-handed parametrisation of the same box).
Trivariate box(const std::array<double, 3>& lo, const std::array<double, 3>& hi, bool flip_u = false) {
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        const int ii = flip_u ? 1 - i : i;
        const double x = ii ? hi[0] : lo[0];
        pts.insert(pts.end(), {x, j ? hi[1] : lo[1], k ? hi[2] : lo[2], x});
      }
  const KnotVector kv(2, {0, 0, 1, 1});
  return Trivariate({kv, kv, kv}, 4, std::move(pts));
}

VModel model_of(std::vector<Trivariate> cells) {
  VModel m;
  m.properties = {"x"};
  for (std::size_t c = 0; c < cells.size(); ++c) m.cells.push_back({std::string("c").append(std::to_string(c)), std::move(cells[c])});
  return m;
}

VModel primitive_model(const construct::Primitive& p) {
  VModel m;
  for (auto& c : construct::build_primitive("p", p)) m.cells.push_back({c.name, std::move(c.volume)});
  return m;
}

/// The smallest distance between two distinct vertices (vertices are welded exactly, so
/// coinciding positions under two indices would show as 0).
double closest_pair(const BoundaryMesh& mesh) {
  auto v = mesh.vertices;
  std::sort(v.begin(), v.end());
  double best = INFINITY;
  for (std::size_t i = 0; i < v.size(); ++i)
    for (std::size_t j = i + 1; j < v.size() && v[j][0] - v[i][0] < best; ++j)
      best = std::min(best, std::hypot(v[j][0] - v[i][0], v[j][1] - v[i][1], v[j][2] - v[i][2]));
  return best;
}

void require_closed(const BoundaryMesh& mesh, int shells, int euler_per_shell = 2) {
  const auto r = edge_report(mesh);
  INFO("boundary edges " << r.boundary_edges << ", non-manifold " << r.non_manifold_edges << ", degenerate "
                         << r.degenerate_triangles);
  REQUIRE(r.manifold());
  REQUIRE(edge_manifold(mesh));
  REQUIRE(shell_count(mesh) == shells);
  REQUIRE(euler_characteristic(mesh) == euler_per_shell * shells);
}

}  // namespace

TEST_CASE("a box cell: 12 triangles, exact volume and area, outward", "[boundary_mesh]") {
  for (bool flip : {false, true}) {
    const auto mesh = mesh_boundary(model_of({box({0, 0, 0}, {2, 3, 4}, flip)}));
    REQUIRE(mesh.triangles.size() == 12);
    REQUIRE(mesh.vertices.size() == 8);
    REQUIRE(mesh.faces == 6);
    REQUIRE(enclosed_volume(mesh) == Approx(24.0).epsilon(1e-14));
    REQUIRE(surface_area(mesh) == Approx(2 * (6 + 8 + 12)).epsilon(1e-14));
    REQUIRE(mesh.cell_volume == Approx(24.0).epsilon(1e-14));
    require_closed(mesh, 1);
    // The property x at each vertex is the vertex's x.
    REQUIRE(mesh.property_names == std::vector<std::string>{"x"});
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v) REQUIRE(mesh.properties[v] == mesh.vertices[v][0]);
  }
}

TEST_CASE("glued cells: interior faces absent, one closed shell, either handedness", "[boundary_mesh]") {
  // An L of three unit cubes, the middle one parametrised left-handed: 14 boundary unit squares.
  const auto model = model_of({box({0, 0, 0}, {1, 1, 1}), box({1, 0, 0}, {2, 1, 1}, true), box({1, 1, 0}, {2, 2, 1})});
  const auto mesh = mesh_boundary(model);
  REQUIRE(mesh.faces == 14);
  REQUIRE(mesh.triangles.size() == 28);
  REQUIRE(mesh.vertices.size() == 16);  // the lattice points of the L's boundary
  REQUIRE(enclosed_volume(mesh) == Approx(3.0).epsilon(1e-14));
  REQUIRE(surface_area(mesh) == Approx(14.0).epsilon(1e-14));
  require_closed(mesh, 1);
  REQUIRE(closest_pair(mesh) == Approx(1.0));

  // Per cell: three closed shells, every face, the sum of the cells' volumes.
  MeshOptions per_cell;
  per_cell.per_cell = true;
  const auto cells = mesh_boundary(model, per_cell);
  REQUIRE(cells.faces == 18);
  REQUIRE(cells.triangles.size() == 36);
  REQUIRE(cells.vertices.size() == 24);
  REQUIRE(enclosed_volume(cells) == Approx(3.0).epsilon(1e-14));
  require_closed(cells, 3);
}

TEST_CASE("collapsed edges: a prism as a box with a face collapsed", "[boundary_mesh]") {
  // x = u, y = v (1 - u), z = w: the u1 face is the segment x = 1, y = 0 (no area, skipped); the
  // edges along v of the u1 face are points, so the w0 and w1 faces are triangles. The prism
  // with the right triangle (0,0) (1,0) (0,1) as base and height 1: volume 1/2, area 3 + sqrt 2.
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) pts.insert(pts.end(), {double(i), double(j * (1 - i)), double(k), double(i)});
  const KnotVector kv(2, {0, 0, 1, 1});
  const auto mesh = mesh_boundary(model_of({Trivariate({kv, kv, kv}, 4, pts)}));
  REQUIRE(mesh.faces == 5);
  REQUIRE(mesh.vertices.size() == 6);
  REQUIRE(mesh.triangles.size() == 8);
  REQUIRE(mesh.dropped_triangles == 2);
  REQUIRE(enclosed_volume(mesh) == Approx(0.5).epsilon(1e-14));
  REQUIRE(surface_area(mesh) == Approx(3.0 + std::sqrt(2.0)).epsilon(1e-14));
  require_closed(mesh, 1);
}

TEST_CASE("a ball of seven cells: watertight, within the tolerance of the sphere", "[boundary_mesh]") {
  const double r = 5.0;
  const auto model = primitive_model(construct::Sphere{{1, 2, 3}, r});
  MeshOptions opt;
  opt.tolerance = 1e-3 * r;
  const auto mesh = mesh_boundary(model, opt);
  REQUIRE(mesh.faces == 6);  // the caps' w1 faces; the cube and the caps' other faces are glued
  require_closed(mesh, 1);
  REQUIRE(mesh.max_deviation <= opt.tolerance);
  REQUIRE(closest_pair(mesh) > 1e-6 * r);  // shared samples are one vertex, not two close ones
  // Every vertex lies on the cells' boundary, which the primitive keeps within 1e-4 r of the
  // sphere (construct/primitives.hpp: half its relative tolerance 2e-4).
  for (const auto& p : mesh.vertices)
    REQUIRE(std::abs(std::hypot(p[0] - 1, p[1] - 2, p[2] - 3) - r) <= 1e-4 * r);
  // The mesh lies within the tolerance inside the spline surface (chords of a convex surface):
  // the volume it misses is at most tol * area, and it misses some.
  const double exact = 4.0 / 3.0 * std::numbers::pi * r * r * r;
  const double area = 4.0 * std::numbers::pi * r * r;
  const double v = enclosed_volume(mesh);
  REQUIRE(v > 0.0);
  REQUIRE(v < mesh.cell_volume);
  REQUIRE(mesh.cell_volume - v <= opt.tolerance * area);
  REQUIRE(std::abs(v - exact) <= (opt.tolerance + 1e-4 * r) * area);
  REQUIRE(std::abs(surface_area(mesh) - area) <= 2.0 * (opt.tolerance + 1e-4 * r) / r * area + 1e-12);
}

TEST_CASE("a cylinder of five cells: the volume error shrinks linearly with the tolerance", "[boundary_mesh]") {
  // Piecewise linear interpolation errs by O(h^2) and the sampling takes h ~ sqrt(tolerance),
  // so the volume error is O(tolerance): a quarter of the tolerance, about a quarter of the error.
  const double r = 2.0, h = 3.0;
  const auto model = primitive_model(construct::Cylinder{{0, 0, 0}, {0, 0, 1}, r, h});
  std::vector<double> errors;
  for (double tol : {1e-3, 2.5e-4, 6.25e-5}) {
    MeshOptions opt;
    opt.tolerance = tol;
    const auto mesh = mesh_boundary(model, opt);
    REQUIRE(mesh.faces == 14);  // 4 curved sides, 5 + 5 on the ends
    require_closed(mesh, 1);
    REQUIRE(mesh.max_deviation <= tol);
    const double err = mesh.cell_volume - enclosed_volume(mesh);
    REQUIRE(err > 0.0);
    REQUIRE(err <= tol * surface_area(mesh));
    errors.push_back(err);
    // The analytic volume, within the tolerance and the primitive's own 1e-4 r.
    REQUIRE(std::abs(enclosed_volume(mesh) - std::numbers::pi * r * r * h) <= (tol + 1e-4 * r) * 2 * std::numbers::pi * r * (r + h));
  }
  for (std::size_t i = 0; i + 1 < errors.size(); ++i) {
    const double order = std::log(errors[i] / errors[i + 1]) / std::log(4.0);
    INFO("errors " << errors[i] << " -> " << errors[i + 1] << ": order " << order);
    REQUIRE(order > 0.7);
    REQUIRE(order < 1.4);
  }
}

TEST_CASE("a torus: cells closed onto themselves, a closed surface of genus 1", "[boundary_mesh]") {
  const auto model = primitive_model(construct::Torus{{0, 0, 0}, {0, 0, 1}, 3.0, 1.0});
  const auto mesh = mesh_boundary(model);
  require_closed(mesh, 1, 0);
  const double exact = 2.0 * std::numbers::pi * std::numbers::pi * 3.0;
  REQUIRE(enclosed_volume(mesh) > 0.0);
  REQUIRE(std::abs(enclosed_volume(mesh) - exact) <= (mesh.tolerance + 1e-4) * 4.0 * std::numbers::pi * std::numbers::pi * 3.0);
}

TEST_CASE("a ring that closes only approximately is closed at the mesh's resolution", "[boundary_mesh]") {
  // Fitted rings (fillets around a sphere's intersection circle) meet themselves within about
  // 1e-5 of their size, not within the topology's default 1e-9: here the end of every torus cell
  // is moved by 1e-7 of the diagonal. Geometry within 1% of the chordal tolerance is glued, so
  // the seam faces are interior and the surface stays closed, of genus 1.
  auto model = primitive_model(construct::Torus{{0, 0, 0}, {0, 0, 1}, 3.0, 1.0});
  for (auto& cell : model.cells) {
    auto& s = cell.volume;
    const auto n = s.counts();
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) s.point(s.row({i, j, n[2] - 1}))[0] += 1e-6;  // diagonal ~ 11.5
  }
  const auto mesh = mesh_boundary(model);
  require_closed(mesh, 1, 0);
}

TEST_CASE("trimmed cells and bad options are refused, naming the cell", "[boundary_mesh]") {
  auto model = model_of({box({0, 0, 0}, {1, 1, 1}), box({0.5, 0, 0}, {2, 1, 1})});
  model.cells[1].name = "cut";
  model.cells[1].within.push_back(model.cells[0]);
  try {
    mesh_boundary(model);
    FAIL("a trimmed cell was meshed");
  } catch (const Error& e) {
    REQUIRE(e.kind() == ErrorKind::bad_input);
    REQUIRE_THAT(e.what(), Catch::Contains("cell \"cut\" (1)") && Catch::Contains("trimmed"));
  }
  MeshOptions bad;
  bad.tolerance = -1;
  REQUIRE_THROWS_AS(mesh_boundary(model_of({box({0, 0, 0}, {1, 1, 1})}), bad), Error);
  MeshOptions fine;
  fine.tolerance = 1e-9;
  fine.max_segments = 64;
  REQUIRE_THROWS_WITH(mesh_boundary(primitive_model(construct::Sphere{{0, 0, 0}, 1.0}), fine),
                      Catch::Contains("expected at most 64"));
}
