// The layer sampler against mathematics: exact voxel counts for unions of axis-aligned cubes
// (the Fichera corner), voxel volumes against quadrature volumes (curved tricubic, rational
// quarter annulus with its closed-form volume, the G+Smo cube, the twisted-column demo model),
// properties against the cell's own evaluation at the located (u,v,w), first-cell-wins on overlap,
// and results independent of how a layer is cut into bands.
#include <catch2/catch.hpp>

#include <filesystem>
#include <numbers>

#include "locator_fixtures.hpp"
#include "trivox/error.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/slice/sampler.hpp"

using namespace trivox;
using namespace trivox::test;
using slice::LayerSampler;
using slice::RowBand;
using slice::VoxelGrid;

namespace {
const std::filesystem::path models = std::filesystem::path(TRIVOX_SOURCE_DIR) / "models";

VoxelGrid grid_for(const vmodel::VModel& m, const std::array<double, 3>& pitch) {
  const auto b = slice::model_bounds(m);
  return VoxelGrid::covering(b[0], b[1], pitch);
}

double voxel_volume(const LayerSampler& s, std::int64_t* failures) {
  const auto& p = s.grid().pitch;
  return static_cast<double>(occupied(s, failures)) * p[0] * p[1] * p[2];
}

double model_volume(const vmodel::VModel& m) {
  double v = 0;
  for (const auto& c : m.cells) v += geom::volume(c.volume);
  return v;
}
}  // namespace

TEST_CASE("sampler: the Fichera corner at 10 mm has exactly the analytic voxel count") {
  const auto m = scaled(io::load_model(models / "gismo" / "fichera.xml"), 10.0);
  // Pitches chosen so that no voxel centre lies on a face (faces at -10, 0, 10; centres at
  // -10 + (i + 1/2) pitch never hit them for these pitches).
  const auto grid = grid_for(m, {0.3, 0.7, 0.45});
  REQUIRE(grid.origin == std::array<double, 3>{-10, -10, -10});
  const LayerSampler s(m, grid);
  // Truth, independently: the cubes are the axis-aligned boxes of their corner points.
  std::vector<std::array<std::vector<double>, 2>> boxes;
  for (const auto& c : m.cells) boxes.push_back(c.volume.control_box());
  std::int64_t count = 0, truth = 0, wrong_cell = 0, failures = 0;
  sample_all(
      s,
      [&](int i, int j, int k, const RowBand& b, int r) {
        const auto p = grid.centre(i, j, k);
        int expect = -1;
        for (std::size_t c = 0; c < boxes.size() && expect < 0; ++c) {
          bool in = true;
          for (std::size_t d = 0; d < 3; ++d) in = in && p[d] > boxes[c][0][d] && p[d] < boxes[c][1][d];
          if (in) expect = static_cast<int>(c);
        }
        truth += expect >= 0;
        count += b.cell_at(r, i) >= 0;
        wrong_cell += b.cell_at(r, i) != expect;
      },
      &failures);
  // The same count in closed form: per axis, centres in [-10, 0] and in [0, 10].
  auto split = [&](int d) {
    int neg = 0;
    for (int i = 0; i < grid.count[static_cast<std::size_t>(d)]; ++i) neg += grid.centre(d == 0 ? i : 0, d == 1 ? i : 0, d == 2 ? i : 0)[static_cast<std::size_t>(d)] < 0;
    int pos = 0;
    for (int i = 0; i < grid.count[static_cast<std::size_t>(d)]; ++i) {
      const double x = grid.centre(d == 0 ? i : 0, d == 1 ? i : 0, d == 2 ? i : 0)[static_cast<std::size_t>(d)];
      pos += x > 0 && x < 10;
    }
    return std::array<std::int64_t, 2>{neg, pos};
  };
  const auto sx = split(0), sy = split(1), sz = split(2);
  std::int64_t all = (sx[0] + sx[1]) * (sy[0] + sy[1]) * (sz[0] + sz[1]);
  // Which octant is missing: the one whose centre no cell contains.
  std::int64_t analytic = 0;
  for (int o = 0; o < 8; ++o) {
    const std::array<double, 3> c{o & 1 ? 5.0 : -5.0, o & 2 ? 5.0 : -5.0, o & 4 ? 5.0 : -5.0};
    bool covered = false;
    for (const auto& bx : boxes) {
      bool in = true;
      for (std::size_t d = 0; d < 3; ++d) in = in && c[d] > bx[0][d] && c[d] < bx[1][d];
      covered = covered || in;
    }
    if (!covered) analytic = all - sx[o & 1 ? 1 : 0] * sy[o & 2 ? 1 : 0] * sz[o & 4 ? 1 : 0];
  }
  CHECK(truth == analytic);
  CHECK(count == analytic);
  CHECK(wrong_cell == 0);
  CHECK(failures == 0);
}

namespace {
/// Checks a sampler against a tight locator (tolerance 1e-10) voxel by voxel: occupancy equal
/// except where the voxel's centre is within the tolerance of a cell boundary, properties within
/// 1/512 of the properties at the exact preimage of the centre, and the stored (u,v,w) mapping
/// within half the smallest pitch of the centre (exactly located voxels: within the tolerance;
/// stepped ones: certified, see sampler.hpp). A disagreement is checked on the side of the cell
/// that claims the voxel: where the truth claims it, its exact parameters lie on the domain's
/// boundary (to within about the tolerance over the Jacobian); where only the sampler does, the
/// centre lies within the sampler's tolerance of that cell (the tight projected Newton over its
/// domain, from the sampler's parameters, ends at most that far from it). The sampler's
/// parameters themselves need not be near the boundary: a stepped voxel's lie within its
/// certified radius of the exact ones (up to half a pitch in xyz), not within the tolerance.
struct Contract {
  std::int64_t inside = 0, boundary_disagreements = 0, failures = 0;
  double worst_prop = 0, worst_residual = 0;
  double worst_outside = 0;  ///< the largest distance (over the tolerance) of a centre claimed by the sampler alone
};
Contract check_contract(const vmodel::VModel& m, const LayerSampler& s, int every = 1) {
  slice::LocatorOptions tight;
  tight.tolerance = 1e-10;
  const slice::Locator truth(m, tight);
  Contract c;
  const double half = 0.5 * std::min({s.grid().pitch[0], s.grid().pitch[1], s.grid().pitch[2]});
  const double tol = s.locator().options().tolerance;
  sample_all(
      s,
      [&](int i, int j, int k, const RowBand& b, int r) {
        const int cell = b.cell_at(r, i);
        c.inside += cell >= 0;
        if ((i + j + k) % every) return;
        const auto p = s.grid().centre(i, j, k);
        const auto lr = truth.locate(p);
        const double* t = cell >= 0 ? &b.uvw[(static_cast<std::size_t>(r) * static_cast<std::size_t>(b.nx) + static_cast<std::size_t>(i)) * 3] : nullptr;
        if (lr.inside != (cell >= 0) || (cell >= 0 && lr.cell != cell)) {
          // Only on a boundary.
          bool on_boundary = true;
          if (lr.inside && (cell < 0 || cell > lr.cell)) {
            // The truth's cell (earlier in file order than the sampler's, if any): its exact
            // parameters are at its domain's boundary.
            const auto dom = s.locator().domain(lr.cell);
            bool near = false;
            for (std::size_t d = 0; d < 3; ++d) near = near || lr.uvw[d] - dom[0][d] < 1e-4 || dom[1][d] - lr.uvw[d] < 1e-4;
            on_boundary = near;
          }
          if (cell >= 0 && (!lr.inside || lr.cell > cell)) {
            // The sampler's cell, which the truth says does not hold the centre: within the
            // sampler's tolerance of it.
            const auto dom = s.locator().domain(cell);
            const auto nr = truth.newton(cell, p, {t[0], t[1], t[2]}, dom[0], dom[1], 200);
            const double dist = nr.status == slice::NewtonStatus::converged ? 0.0 : nr.residual;
            c.worst_outside = std::max(c.worst_outside, dist / tol);
            on_boundary = on_boundary && dist < 1.05 * tol;
          }
          CHECK(on_boundary);
          ++c.boundary_disagreements;
          return;
        }
        if (cell < 0) return;
        const auto& vol = m.cells[static_cast<std::size_t>(cell)].volume;
        const auto exact = vol.eval(lr.uvw);
        const auto at = vol.eval({t[0], t[1], t[2]});
        c.worst_residual = std::max(c.worst_residual, std::hypot(at[0] - p[0], at[1] - p[1], at[2] - p[2]));
        for (std::size_t h = 0; h < m.properties.size(); ++h)
          c.worst_prop = std::max(c.worst_prop, std::abs(double(b.props_at(r, i)[h]) - exact[3 + h]));
      },
      &c.failures);
  INFO("worst property error " << c.worst_prop << ", worst residual " << c.worst_residual << ", worst distance of a centre claimed by the sampler alone "
                                  << c.worst_outside << " x the tolerance");
  CHECK(c.worst_prop < 1.0 / 512);
  CHECK(c.worst_residual < half);
  CHECK(c.failures == 0);
  return c;
}
}  // namespace

TEST_CASE("sampler: curved tricubic cell, voxel volume and properties") {
  const auto m = model_of({curved_tricubic()}, {"r", "g", "b"});
  const auto& cell = m.cells[0].volume;
  // Valid cell: the Jacobian determinant is positive on a fine lattice of parameters.
  for (int k = 0; k <= 10; ++k)
    for (int j = 0; j <= 10; ++j)
      for (int i = 0; i <= 10; ++i) {
        const auto d = cell.eval_derivatives({i / 10.0, j / 10.0, k / 10.0}, 1);
        const double* a = &d[6];
        const double* b = &d[12];
        const double* c = &d[18];
        const double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
        REQUIRE(det > 0);
      }
  const double exact = geom::volume(cell);
  slice::SamplerOptions so;
  so.keep_uvw = true;
  const LayerSampler s(m, grid_for(m, {0.21, 0.23, 0.19}), so);
  const auto c = check_contract(m, s, 3);
  const double vol = static_cast<double>(c.inside) * 0.21 * 0.23 * 0.19;
  INFO("voxel volume " << vol << ", quadrature volume " << exact);
  CHECK(std::abs(vol - exact) < 0.01 * exact);
  CHECK(c.boundary_disagreements < 20);
}

TEST_CASE("sampler: the property contract holds at printer pitch on fast-varying properties") {
  // Properties alternating 0/1 over the control net (large second derivatives: short certified
  // steps), on a curved tricubic block 4 mm wide, at J750 pitches.
  auto cell = curved_tricubic();
  auto pts = cell.points();
  for (int i = 0; i < cell.size(); ++i) {
    const auto idx = cell.multi_index(i);
    pts[static_cast<std::size_t>(i * 6 + 3)] = (idx[0] + idx[1] + idx[2]) % 2;
    pts[static_cast<std::size_t>(i * 6 + 4)] = idx[0] % 2;
    pts[static_cast<std::size_t>(i * 6 + 5)] = idx[2] == 1 ? 1.0 : 0.0;
  }
  const auto m = scaled(model_of({cell}, {"r", "g", "b"}), 0.4);
  slice::SamplerOptions so;
  so.keep_uvw = true;
  const auto j750 = slice::printer_preset("j750");
  const auto b = slice::model_bounds(m);
  auto grid = VoxelGrid::covering(b[0], b[1], {j750.pitch_x(), j750.pitch_y(), j750.pitch_z()});
  // A slab of layers through the middle keeps the test short.
  grid.origin[2] += 60 * grid.pitch[2];
  grid.count[2] = 12;
  const LayerSampler s(m, grid, so);
  const auto c = check_contract(m, s, 1);
  CHECK(c.inside > 40000);
}

TEST_CASE("sampler: rational quarter annulus, voxel volume within 1% of (pi/4)(r2^2 - r1^2) h") {
  const double r1 = 5, r2 = 10, h = 4;
  const auto m = model_of({quarter_annulus(r1, r2, h)}, {"v"});
  const LayerSampler s(m, grid_for(m, {0.1, 0.13, 0.11}));
  std::int64_t failures = 0;
  const double vol = voxel_volume(s, &failures);
  const double exact = std::numbers::pi / 4 * (r2 * r2 - r1 * r1) * h;
  INFO("voxel volume " << vol << ", exact " << exact);
  CHECK(std::abs(vol - exact) < 0.01 * exact);
  CHECK(failures == 0);
  // Every voxel's occupancy equals the analytic test (no centre is within the tolerance of
  // the boundary at this grid, checked below) and its property (= v) is the radial fraction.
  std::int64_t wrong = 0;
  double worst = 0;
  sample_all(s, [&](int i, int j, int k, const RowBand& b, int r) {
    const auto p = s.grid().centre(i, j, k);
    const double rho = std::hypot(p[0], p[1]);
    const double margin = std::min({std::abs(rho - r1), std::abs(rho - r2), std::abs(p[0]), std::abs(p[1]), std::abs(p[2]), std::abs(p[2] - h)});
    const bool truth = rho > r1 && rho < r2 && p[0] > 0 && p[1] > 0 && p[2] > 0 && p[2] < h;
    if (margin < 1e-3 * 0.1) return;
    wrong += truth != (b.cell_at(r, i) >= 0);
    if (truth) worst = std::max(worst, std::abs(double(b.props_at(r, i)[0]) - (rho - r1) / (r2 - r1)));
  });
  CHECK(wrong == 0);
  CHECK(worst < 1.0 / 512);
}

TEST_CASE("sampler: G+Smo cube, voxel volume within 1% of 27") {
  const auto m = io::load_model(models / "gismo" / "cube.xml");
  const LayerSampler s(m, grid_for(m, {0.05, 0.06, 0.055}));
  std::int64_t failures = 0;
  const double vol = voxel_volume(s, &failures);
  INFO("voxel volume " << vol);
  CHECK(std::abs(vol - 27.0) < 0.27);
  CHECK(failures == 0);
}

TEST_CASE("sampler: twisted column demo model, voxel volume within 1% of its quadrature volume") {
  const auto m = io::load_model(models / "twisted_column.json");
  const auto b = slice::model_bounds(m);
  const double size = std::max({b[1][0] - b[0][0], b[1][1] - b[0][1], b[1][2] - b[0][2]});
  const double pitch = size / 80;
  slice::SamplerOptions so;
  so.keep_uvw = true;
  const LayerSampler s(m, grid_for(m, {pitch, 1.1 * pitch, 0.9 * pitch}), so);
  const auto c = check_contract(m, s, 2);
  const double vol = static_cast<double>(c.inside) * pitch * 1.1 * pitch * 0.9 * pitch;
  const double exact = model_volume(m);
  INFO("voxel volume " << vol << ", quadrature volume " << exact);
  CHECK(std::abs(vol - exact) < 0.01 * exact);
}

TEST_CASE("sampler: the contract holds at J750 pitch on the twisted column (anchors near slanted faces)") {
  // The print job's bench model at printer pitch: its rings' faces cross the image rows at a
  // slant, so a run's first anchor certifies each row of its block with columns of its own.
  const auto m = io::load_model(models / "twisted_column.json");
  const auto j750 = slice::printer_preset("j750");
  const auto b = slice::model_bounds(m);
  auto grid = VoxelGrid::covering(b[0], b[1], {j750.pitch_x(), j750.pitch_y(), j750.pitch_z()});
  grid.origin[2] += 90 * grid.pitch[2];  // two layers inside the first ring
  grid.count[2] = 2;
  slice::SamplerOptions so;
  so.keep_uvw = true;
  const LayerSampler s(m, grid, so);
  CHECK(check_contract(m, s, 3).inside > 300000);
}

TEST_CASE("sampler: overlapping cells, the first in file order wins") {
  const auto a = box_cell({0, 0, 0}, {2, 2, 2}, {1});
  const auto b = box_cell({1, 1, 1}, {3, 3, 3}, {2});
  for (int order = 0; order < 2; ++order) {
    const auto m = order ? model_of({b, a}, {"p"}) : model_of({a, b}, {"p"});
    const LayerSampler s(m, grid_for(m, {0.3, 0.3, 0.3}));
    std::int64_t mismatches = 0, in_both = 0;
    sample_all(s, [&](int i, int j, int k, const RowBand& band, int r) {
      const auto p = s.grid().centre(i, j, k);
      const bool ina = p[0] < 2 && p[1] < 2 && p[2] < 2, inb = p[0] > 1 && p[1] > 1 && p[2] > 1;
      const int ia = order ? 1 : 0, ib = order ? 0 : 1;
      const int expect = ina && inb ? 0 : ina ? ia : inb ? ib : -1;
      in_both += ina && inb;
      mismatches += band.cell_at(r, i) != expect;
      if (expect >= 0) mismatches += band.props_at(r, i)[0] != (expect == ia ? 1.0f : 2.0f);
    });
    CHECK(in_both > 0);
    CHECK(mismatches == 0);
  }
}

TEST_CASE("sampler: without clearing void voxels' properties, the same cells and the same properties elsewhere") {
  // SamplerOptions::zero_void_props = false (the print job): the band's void voxels keep what it
  // held (here a marker), every other voxel is as with the clearing; in bands that are whole
  // blocks (written in place) and not (through the sampler's scratch).
  const auto m = model_of({curved_tricubic()}, {"r", "g", "b"});
  const auto grid = grid_for(m, {0.17, 0.29, 0.31});
  slice::SamplerOptions keep;
  keep.zero_void_props = false;
  const LayerSampler cleared(m, grid), kept(m, grid, keep);
  const int ny = grid.count[1];
  std::int64_t voids = 0, marked = 0, live = 0;
  for (int k : {2, grid.count[2] / 2})
    for (const auto& [row0, rows] : std::vector<std::pair<int, int>>{{0, ny}, {4, 8}, {3, 6}}) {
      RowBand want, got;
      cleared.sample(k, row0, rows, want);
      got.props.assign(want.props.size(), 7.0f);  // the band's old contents
      kept.sample(k, row0, rows, got);
      REQUIRE(got.cell == want.cell);
      for (std::size_t v = 0; v < want.cell.size(); ++v)
        for (std::size_t h = 0; h < 3; ++h) {
          const float w = want.props[3 * v + h], g = got.props[3 * v + h];
          if (want.cell[v] < 0) {
            voids += h == 0;
            CHECK(w == 0.0f);
            marked += g == 7.0f;
          } else {
            live += h == 0;
            CHECK(g == w);
          }
        }
    }
  CHECK(live > 100);
  CHECK(voids > 100);
  CHECK(marked > 0);  // the clearing was skipped
}

TEST_CASE("sampler: a layer cut into bands gives the same result as in one piece") {
  const auto m = model_of({curved_tricubic(), quarter_annulus(5, 10, 4)}, {"r", "g", "b"});
  auto m2 = m;
  // The annulus has one property in its fixture; give it three (v, 0, 1) to match the model.
  {
    const auto& q = m.cells[1].volume;
    std::vector<double> pts;
    for (int i = 0; i < q.size(); ++i) {
      const auto p = q.point(i);
      pts.insert(pts.end(), {p[0], p[1], p[2], p[3], 0.0, 1.0});
    }
    m2.cells[1].volume = Trivariate(q.knot_vectors(), 6, pts, q.weights());
  }
  const LayerSampler s(m2, grid_for(m2, {0.17, 0.29, 0.31}));
  const int ny = s.grid().count[1];
  for (int k : {3, s.grid().count[2] / 2}) {
    RowBand whole, part;
    s.sample(k, 0, ny, whole);
    std::int64_t inside = 0;
    for (auto c : whole.cell) inside += c >= 0;
    CHECK(inside > 100);
    for (int row0 = 0; row0 < ny; row0 += 7) {
      const int rows = std::min(7, ny - row0);
      s.sample(k, row0, rows, part);
      REQUIRE(part.rows == rows);
      for (int r = 0; r < rows; ++r)
        for (int i = 0; i < part.nx; ++i) {
          REQUIRE(part.cell_at(r, i) == whole.cell_at(row0 + r, i));
          for (int h = 0; h < 3; ++h) REQUIRE(part.props_at(r, i)[h] == whole.props_at(row0 + r, i)[h]);
        }
    }
  }
}

TEST_CASE("sampler: bad layer or rows are reported") {
  const auto m = model_of({box_cell({0, 0, 0}, {1, 1, 1})});
  const LayerSampler s(m, grid_for(m, {0.25, 0.25, 0.25}));
  RowBand b;
  CHECK_THROWS_AS(s.sample(-1, 0, 1, b), Error);
  CHECK_THROWS_AS(s.sample(4, 0, 1, b), Error);
  CHECK_THROWS_AS(s.sample(0, 3, 2, b), Error);
  CHECK_NOTHROW(s.sample(0, 4, 0, b));
  s.sample(1, 0, 4, b);
  CHECK(b.cell.size() == 16);
  for (auto c : b.cell) CHECK(c == 0);
}

TEST_CASE("sampler: at printer pitch, bands of any size give identical results") {
  const auto m = io::load_model(models / "twisted_column.json");
  const auto j750 = slice::printer_preset("j750");
  const auto b = slice::model_bounds(m);
  const LayerSampler s(m, VoxelGrid::covering(b[0], b[1], {j750.pitch_x(), j750.pitch_y(), j750.pitch_z()}));
  const int ny = s.grid().count[1];
  for (int k : {100, s.grid().count[2] / 2}) {
    RowBand whole, part;
    s.sample(k, 0, ny, whole);
    std::int64_t inside = 0;
    for (auto c : whole.cell) inside += c >= 0;
    CHECK(inside > 100000);
    for (int step : {1, 5, 13}) {
      std::int64_t mismatches = 0;
      for (int row0 = 0; row0 < ny; row0 += step) {
        const int rows = std::min(step, ny - row0);
        s.sample(k, row0, rows, part);
        for (int r = 0; r < rows; ++r)
          for (int i = 0; i < part.nx; ++i) {
            mismatches += part.cell_at(r, i) != whole.cell_at(row0 + r, i);
            for (int h = 0; h < part.nprops; ++h) mismatches += part.props_at(r, i)[h] != whole.props_at(row0 + r, i)[h];
          }
      }
      CHECK(mismatches == 0);
    }
  }
}

TEST_CASE("sampler: the contract holds at printer pitch for overlapping, rational and many-property cells") {
  const auto j750 = slice::printer_preset("j750");
  slice::SamplerOptions so;
  so.keep_uvw = true;
  auto thin_grid = [&](const vmodel::VModel& m, int layers) {
    const auto b = slice::model_bounds(m);
    auto g = VoxelGrid::covering(b[0], b[1], {j750.pitch_x(), j750.pitch_y(), j750.pitch_z()});
    g.origin[2] += (g.count[2] / 2) * g.pitch[2];
    g.count[2] = layers;
    return g;
  };
  SECTION("two overlapping curved cells: the first wins") {
    auto a = curved_tricubic(), b = curved_tricubic();
    auto pb = b.points();
    for (int i = 0; i < b.size(); ++i) {
      pb[static_cast<std::size_t>(i * 6)] += 4.0;
      pb[static_cast<std::size_t>(i * 6 + 3)] = 0.25;
    }
    const auto m = scaled(model_of({a, b}, {"r", "g", "b"}), 0.5);
    const LayerSampler s(m, thin_grid(m, 3), so);
    CHECK(check_contract(m, s, 1).inside > 20000);
  }
  SECTION("the twisted column (the bench's model): its rows' properties from exact samples") {
    // Nearly affine cells with cubic colour fields: the anchors reach across the cells, and
    // their properties come from the piece's polynomial every few dozen voxels (run_interpolation.cpp).
    const auto m = io::load_model(models / "twisted_column.json");
    const LayerSampler s(m, thin_grid(m, 2), so);
    CHECK(check_contract(m, s, 3).inside > 300000);
  }
  SECTION("rational quarter annulus") {
    const auto m = model_of({quarter_annulus(2, 4, 1)}, {"v"});
    const LayerSampler s(m, thin_grid(m, 2), so);
    CHECK(check_contract(m, s, 1).inside > 4000);
  }
  SECTION("nine properties: no stepping, every voxel evaluated") {
    auto c = curved_tricubic();
    std::vector<double> pts;
    for (int i = 0; i < c.size(); ++i) {
      const auto p = c.point(i);
      pts.insert(pts.end(), p.begin(), p.end());
      for (int h = 0; h < 6; ++h) pts.push_back(p[static_cast<std::size_t>(3 + h % 3)] * (h + 1) / 7.0);
    }
    const auto m = scaled(model_of({Trivariate(c.knot_vectors(), 12, pts)}, {"a", "b", "c", "d", "e", "f", "g", "h", "i"}), 0.3);
    const LayerSampler s(m, thin_grid(m, 2), so);
    CHECK(check_contract(m, s, 1).inside > 4000);
  }
}

TEST_CASE("sampler: a wedge, one face collapsed onto an edge (zero Jacobian there), has volume 500") {
  // Trilinear: the face w = 1 is the segment x in [0, 10], y = 5, z = 10; cross-sections shrink
  // linearly, so the volume is 10 * integral_0^10 10 (1 - z / 10) dz = 500.
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) pts.insert(pts.end(), {10.0 * i, k ? 5.0 : 10.0 * j, 10.0 * k, 1.0});
  const auto lin = spline::KnotVector::bezier(2);
  const auto m = model_of({Trivariate({lin, lin, lin}, 4, pts)}, {"p"});
  const LayerSampler s(m, grid_for(m, {0.1, 0.11, 0.09}));
  std::int64_t failures = 0;
  const double vol = voxel_volume(s, &failures);
  INFO("voxel volume " << vol);
  CHECK(std::abs(vol - 500.0) < 5.0);
  CHECK(failures == 0);
}

TEST_CASE("sampler: the contract holds on a thin curved shell at printer pitch (the scaled certificate)") {
  // A quarter of a cylindrical wall 2 mm thick at radius 20 mm (u: a cubic Bezier arc, v:
  // radial, w: along z), like the teapot's body: in the plain parameter norm its curvature term
  // refuses anchors after a few voxels, in the norm scaled by |dX/dt_j| they span the wall.
  // The scaled proof must keep the contract: occupancy, properties within 1/512, volume.
  const double r1 = 18, r2 = 20, h = 1, k = 4.0 / 3.0 * (std::sqrt(2.0) - 1.0);
  std::vector<double> pts;
  for (int c = 0; c < 2; ++c)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 4; ++i) {
        const double r = j ? r2 : r1;
        const double xy[4][2] = {{r, 0}, {r, k * r}, {k * r, r}, {0, r}};
        pts.insert(pts.end(), {xy[i][0], xy[i][1], c * h, 0.2 + 0.2 * i, 0.3 + 0.4 * j, 0.5 + 0.3 * c * (i % 2)});
      }
  const auto cub = spline::KnotVector::bezier(4), lin = spline::KnotVector::bezier(2);
  const auto m = model_of({Trivariate({cub, lin, lin}, 6, pts)}, {"r", "g", "b"});
  slice::SamplerOptions so;
  so.keep_uvw = true;
  const auto j750 = slice::printer_preset("j750");
  const auto b = slice::model_bounds(m);
  auto grid = VoxelGrid::covering(b[0], b[1], {j750.pitch_x(), j750.pitch_y(), j750.pitch_z()});
  grid.origin[2] += 15 * grid.pitch[2];
  grid.count[2] = 4;
  const LayerSampler s(m, grid, so);
  const auto c = check_contract(m, s, 2);
  const double vol = static_cast<double>(c.inside) * grid.pitch[0] * grid.pitch[1] * grid.pitch[2];
  const double exact = geom::volume(m.cells[0].volume) * 4 * grid.pitch[2] / h;
  INFO("voxel volume " << vol << ", quadrature volume of the slab " << exact);
  CHECK(std::abs(vol - exact) < 0.01 * exact);
}

TEST_CASE("sampler: a layer through the faces between stacked cells, and layer-thin cells") {
  // The demo column (four cells stacked along z) squashed to one J750 layer: each cell is
  // 6.75 um thick and layer 0's centre lies exactly on the face between the second and third
  // cell, so every voxel of it is a boundary voxel. The contract still holds, the first cell
  // takes the face, and the certified path (not one evaluation per voxel) carries the layer.
  auto m = io::load_model(models / "twisted_column.json");
  const auto b = slice::model_bounds(m);
  for (auto& c : m.cells)
    for (int r = 0; r < c.volume.size(); ++r) {
      auto p = c.volume.point(r);
      p[2] = (p[2] - b[0][2]) * 0.027 / (b[1][2] - b[0][2]);
    }
  const auto j750 = slice::printer_preset("j750");
  const auto bb = slice::model_bounds(m);
  auto grid = VoxelGrid::covering(bb[0], bb[1], {j750.pitch_x(), j750.pitch_y(), j750.pitch_z()});
  grid.count[2] = 1;
  REQUIRE(grid.centre(0, 0, 0)[2] == Approx(0.0135).margin(1e-15));
  slice::SamplerOptions so;
  so.keep_uvw = true;
  const LayerSampler s(m, grid, so);
  const auto c = check_contract(m, s, 3);
  CHECK(c.inside > 100000);
  RowBand band;
  s.sample(0, 0, grid.count[1], band);
  std::int64_t second = 0, other = 0;
  for (auto cell : band.cell) (cell == 1 ? second : other) += cell >= 0;
  CHECK(second > 200000);
  CHECK(other < second / 100);  // the third cell only where the second one does not reach
}
