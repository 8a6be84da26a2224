// Topology of V-models (Massarwi & Elber 2016, Sec. 3.1). Expected counts come from an
// independent enumeration of unit lattice squares, segments and points of unions of unit cubes,
// from counting by hand (each checked against Euler's V - E + F - C = 1 for a solid ball), or
// from evaluating the cells directly.
#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include "trivox/error.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/spline/refine.hpp"
#include "trivox/vmodel/topology.hpp"

#include "trivox/io/model_file.hpp"

using namespace trivox;
using namespace trivox::vmodel;
using spline::Face;
using spline::KnotVector;
using spline::Trivariate;

namespace {

using Lattice = std::array<int, 3>;

/// The trilinear cell [lo, lo + size]^3 with `props` extra property coordinates set to `value`.
Trivariate box(const std::array<double, 3>& lo, double size = 1.0, int props = 0, double value = 0.0) {
  const int dim = 3 + props;
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        pts.insert(pts.end(), {lo[0] + i * size, lo[1] + j * size, lo[2] + k * size});
        for (int p = 0; p < props; ++p) pts.push_back(value + i + p);
      }
  const KnotVector kv(2, {0, 0, 1, 1});
  return Trivariate({kv, kv, kv}, dim, std::move(pts));
}

VModel model_of(std::vector<Trivariate> cells, int props = 0) {
  VModel m;
  // Names built by appending: GCC 12 warns falsely (-Wrestrict) on "literal" + std::string.
  for (int p = 0; p < props; ++p) m.properties.push_back(std::string("p").append(std::to_string(p)));
  for (std::size_t c = 0; c < cells.size(); ++c)
    m.cells.push_back({std::string("c").append(std::to_string(c)), std::move(cells[c])});
  return m;
}

/// Counts of a union of unit lattice cubes (given by their minimum corners), by enumeration of
/// lattice points, unit segments and unit squares: a square used by two cubes is interior.
TopologyCounts lattice_counts(const std::vector<Lattice>& cubes) {
  std::set<Lattice> points;
  std::set<std::pair<Lattice, int>> segments;  // start point, axis
  std::map<std::pair<Lattice, int>, int> squares;  // min corner, normal axis -> uses
  for (const auto& c : cubes) {
    for (int k = 0; k < 8; ++k) points.insert({c[0] + (k & 1), c[1] + ((k >> 1) & 1), c[2] + ((k >> 2) & 1)});
    for (int axis = 0; axis < 3; ++axis)
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
          Lattice p = c;
          p[(axis + 1) % 3] += a;
          p[(axis + 2) % 3] += b;
          segments.insert({p, axis});
        }
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        Lattice p = c;
        p[axis] += side;
        ++squares[{p, axis}];
      }
  }
  TopologyCounts out;
  out.v_cells = static_cast<int>(cubes.size());
  out.v_points = static_cast<int>(points.size());
  out.v_curves = static_cast<int>(segments.size());
  out.v_surfaces = static_cast<int>(squares.size());
  for (const auto& [sq, uses] : squares) out.half_v_surfaces += uses;
  return out;
}

std::vector<Lattice> fichera_cubes() {
  std::vector<Lattice> cubes;
  for (int z = -1; z <= 0; ++z)
    for (int y = -1; y <= 0; ++y)
      for (int x = -1; x <= 0; ++x)
        if (!(x == 0 && y == 0 && z == 0)) cubes.push_back({x, y, z});
  return cubes;
}

std::vector<Trivariate> boxes(const std::vector<Lattice>& cubes) {
  std::vector<Trivariate> out;
  for (const auto& c : cubes) out.push_back(box({double(c[0]), double(c[1]), double(c[2])}));
  return out;
}

/// Point of face f of s at normalised (s, t), by the spline kernel's own boundary_face.
std::array<double, 3> face_point(const Trivariate& s, Face f, std::array<double, 2> st) {
  const auto face = spline::boundary_face(s, f);
  const auto d0 = face.domain(0), d1 = face.domain(1);
  const auto p = face.eval({d0[0] + st[0] * (d0[1] - d0[0]), d1[0] + st[1] * (d1[1] - d1[0])});
  return {p[0], p[1], p[2]};
}

/// Every glued pair is the same point set under its reported orientation.
void check_glue_orientations(const VModel& m, const Topology& topo) {
  for (const auto& g : glued_faces(topo)) {
    for (double s : {0.0, 0.2, 0.7, 1.0})
      for (double t : {0.0, 0.4, 0.9, 1.0}) {
        const auto a = face_point(m.cells[std::size_t(g.cell)].volume, g.face, {s, t});
        const auto b = face_point(m.cells[std::size_t(g.neighbour)].volume, g.neighbour_face, g.orientation.apply({s, t}));
        for (int h = 0; h < 3; ++h) REQUIRE(a[std::size_t(h)] == Approx(b[std::size_t(h)]).margin(1e-12));
      }
  }
}

/// A quarter of the cylinder r <= 1, 0 <= z <= 1 (u: radius 0..1, v: angle 0..90 degrees as a
/// rational quadratic arc, w: height), rotated by `quarter` * 90 degrees. Face u0 is the axis.
Trivariate quarter_cylinder(int quarter) {
  const double r = std::sqrt(0.5);
  const std::array<std::array<double, 3>, 3> arc{{{1, 0, 1}, {1, 1, r}, {0, 1, 1}}};  // x, y, weight
  std::vector<double> pts, w;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 2; ++i) {
        double x = i * arc[std::size_t(j)][0], y = i * arc[std::size_t(j)][1];
        for (int q = 0; q < quarter; ++q) {  // exact rotations by 90 degrees
          const double t = x;
          x = -y;
          y = t;
        }
        pts.insert(pts.end(), {x, y, double(k)});
        w.push_back(arc[std::size_t(j)][2]);
      }
  const KnotVector lin(2, {0, 0, 1, 1}), quad(3, {0, 0, 0, 1, 1, 1});
  return Trivariate({lin, quad, lin}, 3, std::move(pts), std::move(w));
}

}  // namespace

TEST_CASE("orientations compose with their inverses") {
  for (int i = 0; i < 8; ++i) {
    const auto o = Orientation::from_index(i);
    CHECK(o.index() == i);
    for (std::array<double, 2> st : {std::array<double, 2>{0.1, 0.7}, {0.0, 1.0}, {0.35, 0.35}}) {
      const auto back = o.inverse().apply(o.apply(st));
      CHECK(back[0] == Approx(st[0]));
      CHECK(back[1] == Approx(st[1]));
    }
  }
  CHECK(Orientation{true, true, false}.apply({0.25, 0.5})[0] == Approx(0.5));
  CHECK(Orientation{true, true, false}.apply({0.25, 0.5})[1] == Approx(0.25));
}

TEST_CASE("the Fichera corner of 7 unit cubes") {
  const auto cubes = fichera_cubes();
  const VModel m = model_of(boxes(cubes));
  const Topology topo = build_topology(m);
  // By hand: 27 lattice points of [-1,1]^3 but (1,1,1); 54 unit segments of the 2x2x2 block but
  // the 3 at (1,1,1); 36 unit squares but the 3 at x, y or z = 1 of the missing octant; 7 * 6
  // half-V-surfaces. Euler: 26 - 51 + 33 - 7 = 1.
  const TopologyCounts expected{7, 33, 42, 51, 26};
  CHECK(lattice_counts(cubes) == expected);
  CHECK(counts(topo) == expected);
  // 12 - 3 interior squares of the block, each glued from both sides.
  CHECK(glued_faces(topo).size() == 18);
  int boundary = 0;
  for (const auto& s : topo.v_surfaces) boundary += s.boundary() ? 1 : 0;
  CHECK(boundary == 24);
  check_glue_orientations(m, topo);
  // Cube (-1,-1,-1) is cell 0; its face neighbours are (0,-1,-1), (-1,0,-1), (-1,-1,0).
  CHECK(neighbours(topo, 0) == std::vector<int>{1, 2, 4});
  // Cube (0,0,-1) (cell 3) and cube (-1,-1,0) (cell 4) share only the point (0,0,0); cube 0
  // and cube 3 the segment x = y = 0, z in [-1, 0].
  CHECK(contact(topo, 3, 4) == Contact::point);
  CHECK(contact(topo, 0, 3) == Contact::curve);
  CHECK(contact(topo, 0, 1) == Contact::surface);
  // The centre (0,0,0) is a corner of all 7 cubes; the segment from (0,0,-1) to (0,0,0) an edge of 4.
  const int centre = topo.cell_corners[0][7];
  CHECK(cells_around_point(topo, centre).size() == 7);
  const int axis = topo.cell_edges[0][11];  // cell 0 along w with u, v at their maximum
  CHECK(cells_around_curve(topo, axis) == std::vector<int>{0, 1, 2, 3});
  CHECK(topo.v_curves[std::size_t(axis)].v_surfaces.size() == 4);
  for (const auto& c : topo.v_curves) CHECK(c.v_points[0] != c.v_points[1]);
  CHECK_THROWS_AS(neighbours(topo, 7), Error);
}

TEST_CASE("gluing sees through orientation, function space and parametric domain") {
  std::vector<Lattice> cubes;
  for (int z = 0; z < 2; ++z)
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 2; ++x) cubes.push_back({x, y, z});
  auto cells = boxes(cubes);
  cells[0] = spline::reverse(cells[0], 0);
  {
    const std::vector<double> knots{0.3, 0.3, 0.8};
    Trivariate t = spline::swap_directions(cells[3], 0, 2);
    t = spline::elevate(t, 1, 2);
    t = spline::refine(t, 0, std::span<const double>(knots));
    cells[3] = spline::reverse(t, 1);
  }
  cells[5] = spline::reparametrize(spline::swap_directions(cells[5], 0, 1), 2, 2.0, 5.0);
  {  // the same geometry as a rational spline of weight 2 everywhere, refined in w
    Trivariate& s = cells[6];
    s = Trivariate(s.knot_vectors(), 3, std::vector<double>(s.points().begin(), s.points().end()),
                   std::vector<double>(std::size_t(s.size()), 2.0));
    s = spline::refine_uniform(spline::elevate(s, 2, 1), 2, 2);
  }
  const VModel m = model_of(cells);
  const Topology topo = build_topology(m);
  const TopologyCounts expected{8, 36, 48, 54, 27};
  CHECK(lattice_counts(cubes) == expected);
  CHECK(counts(topo) == expected);
  CHECK(glued_faces(topo).size() == 24);
  check_glue_orientations(m, topo);
  for (int c = 0; c < 8; ++c) CHECK(neighbours(topo, c).size() == 3);
  // Every face had area, every half-V-surface knows its four edges.
  for (const auto& h : topo.half_v_surfaces)
    for (int q : h.v_curves) CHECK(q >= 0);
}

TEST_CASE("properties are ignored") {
  const VModel m = model_of({box({0, 0, 0}, 1.0, 2, 0.0), box({1, 0, 0}, 1.0, 2, 5.0)}, 2);
  const Topology topo = build_topology(m);
  CHECK(counts(topo) == TopologyCounts{2, 11, 12, 20, 12});
  CHECK(neighbours(topo, 0) == std::vector<int>{1});
  const auto g = glued_faces(topo);
  REQUIRE(g.size() == 2);
  CHECK(g[0].cell == 0);
  CHECK(g[0].face == Face::u1);
  CHECK(g[0].neighbour == 1);
  CHECK(g[0].neighbour_face == Face::u0);
  CHECK(g[0].orientation == Orientation{});
}

TEST_CASE("faces that do not coincide are not glued") {
  SECTION("half overlap") {
    // [0,1]^3 and [1,2] x [0.5,1.5] x [0,1]: no shared corner, edge or face.
    const Topology topo = build_topology(model_of({box({0, 0, 0}), box({1, 0.5, 0})}));
    CHECK(counts(topo) == TopologyCounts{2, 12, 12, 24, 16});
    CHECK(contact(topo, 0, 1) == Contact::none);
  }
  SECTION("a gap above the tolerance, closed by a larger tolerance") {
    const VModel m = model_of({box({0, 0, 0}), box({1 + 1e-6, 0, 0})});
    CHECK(counts(build_topology(m)) == TopologyCounts{2, 12, 12, 24, 16});
    TopologyOptions loose;
    loose.relative_tolerance = 1e-5;
    const Topology topo = build_topology(m, loose);
    CHECK(counts(topo) == TopologyCounts{2, 11, 12, 20, 12});
    CHECK(topo.tolerance == Approx(1e-5 * std::sqrt(4.0 + 1e-6 * 4 + 1e-12 + 2.0)).epsilon(1e-3));
  }
  SECTION("a face bulging in its interior, same boundary") {
    // The second cell's u0 face has the same edges as the first cell's u1 face, but its middle
    // is pushed out: the edges and corners are shared, the face is not.
    Trivariate b = spline::elevate(spline::elevate(box({1, 0, 0}), 1, 1), 2, 1);
    b.point(b.row({0, 1, 1}))[0] += 0.2;
    const Topology topo = build_topology(model_of({box({0, 0, 0}), b}));
    CHECK(counts(topo) == TopologyCounts{2, 12, 12, 20, 12});
    CHECK(contact(topo, 0, 1) == Contact::curve);
  }
}

TEST_CASE("faces and edges collapsed to a curve or a point are not counted") {
  SECTION("one quarter cylinder") {
    // Faces: u0 collapses onto the axis; u1 (curved side), v0, v1 (planes), w0, w1 (quarter
    // disks) remain. Edges: 4 radial (along u), 2 arcs (along v at u = 1; those at u = 0 are
    // points), 3 vertical (along w: the axis twice, merged, and 2 at the rim). Corners: 2 on the
    // axis, 4 on the rim. Euler: 6 - 9 + 5 = 2.
    const Topology topo = build_topology(model_of({quarter_cylinder(0)}));
    CHECK(counts(topo) == TopologyCounts{1, 5, 5, 9, 6});
    CHECK(topo.cell_faces[0][0] == -1);
    CHECK(topo.cell_edges[0][4] == -1);  // along v at u = 0, w = 0
    CHECK(topo.cell_edges[0][8] == topo.cell_edges[0][10]);  // the axis from v = 0 and v = 1
  }
  SECTION("four quarters make the cylinder") {
    // 4 interior planes, 4 side + 4 top + 4 bottom boundary faces; 1 axis, 8 radial, 8 arcs, 4
    // rim verticals; 2 axis ends, 8 rim points. Euler: 10 - 21 + 16 - 4 = 1.
    const VModel m = model_of({quarter_cylinder(0), quarter_cylinder(1), quarter_cylinder(2), quarter_cylinder(3)});
    const Topology topo = build_topology(m);
    CHECK(counts(topo) == TopologyCounts{4, 16, 20, 21, 10});
    check_glue_orientations(m, topo);
    const int axis = topo.cell_edges[0][8];
    CHECK(cells_around_curve(topo, axis) == std::vector<int>{0, 1, 2, 3});
    CHECK(neighbours(topo, 0) == std::vector<int>{1, 3});
    CHECK(contact(topo, 0, 2) == Contact::curve);
    // The axis bounds the 4 interior planes; the faces collapsed onto it are not surfaces.
    CHECK(topo.v_curves[std::size_t(axis)].v_surfaces.size() == 4);
  }
}

TEST_CASE("a large block glues in linear time") {
  const int n = 14;  // 2744 cells
  std::vector<Lattice> cubes;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) cubes.push_back({x, y, z});
  const VModel m = model_of(boxes(cubes));
  const auto start = std::chrono::steady_clock::now();
  const Topology topo = build_topology(m);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // (n+1)^3 points, 3 n (n+1)^2 segments, 3 n^2 (n+1) squares, 6 n^3 half-squares.
  const TopologyCounts expected{n * n * n, 3 * n * n * (n + 1), 6 * n * n * n, 3 * n * (n + 1) * (n + 1),
                                (n + 1) * (n + 1) * (n + 1)};
  CHECK(lattice_counts(cubes) == expected);
  CHECK(counts(topo) == expected);
  CHECK(seconds < 20.0);  // pairwise comparison would take (2744 * 6)^2 / 2 face tests
}

TEST_CASE("bad options and bad cells are reported") {
  const VModel m = model_of({box({0, 0, 0})});
  TopologyOptions o;
  o.samples = 1;
  CHECK_THROWS_WITH(build_topology(m, o), Catch::Contains("samples 1"));
  o = {};
  o.relative_tolerance = -1;
  CHECK_THROWS_WITH(build_topology(m, o), Catch::Contains("relative_tolerance"));
  o = {};
  o.area_samples = 0;
  CHECK_THROWS_AS(build_topology(m, o), Error);
  VModel flat;
  const KnotVector kv(2, {0, 0, 1, 1});
  flat.cells.push_back({"flat", Trivariate({kv, kv, kv}, 2, std::vector<double>(16, 0.0))});
  CHECK_THROWS_WITH(build_topology(flat), Catch::Contains("\"flat\""));
  CHECK(counts(build_topology(VModel{})) == TopologyCounts{});
}

TEST_CASE("the G+Smo fixtures") {
  const std::filesystem::path dir = std::filesystem::path(TRIVOX_SOURCE_DIR) / "models" / "gismo";
  SECTION("fichera.xml: the same lattice as the hand-built Fichera corner") {
    const VModel m = io::load_model(dir / "fichera.xml");
    CHECK(counts(build_topology(m)) == lattice_counts(fichera_cubes()));
  }
  SECTION("cube.xml: [-1,2]^3 as a unit cube and six frustums") {
    // V-points: the 8 corners of the inner cube [0,1]^3 and the 8 of the outer one: 16.
    // V-curves: 12 inner-cube edges, 12 outer-cube edges, and 8 diagonals joining each inner
    // corner to the outer corner beyond it (shared by the 3 frustums around it): 32.
    // V-surfaces: the inner cube's 6 faces (each glued to one frustum), the 6 outer faces (one
    // per frustum, boundary) and the 12 trapezoids between two neighbouring frustums (one per
    // cube edge): 24. Half-V-surfaces: 7 * 6 = 42 = 2 * (6 + 12) + 6.
    // Euler: 16 - 32 + 24 - 7 = 1.
    const VModel m = io::load_model(dir / "cube.xml");
    const Topology topo = build_topology(m);
    CHECK(counts(topo) == TopologyCounts{7, 24, 42, 32, 16});
    check_glue_orientations(m, topo);
    int centre = -1;
    for (int c = 0; c < 7; ++c)
      if (neighbours(topo, c).size() == 6) centre = c;
    REQUIRE(centre >= 0);
    for (int c = 0; c < 7; ++c)
      if (c != centre) CHECK(neighbours(topo, c).size() == 5);  // the cube and 4 frustums
  }
}
