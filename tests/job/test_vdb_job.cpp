// The VDB job's units, colour space and grid names (job/vdb_job.hpp), read back by OpenVDB
// through io::inspect_vdb. The model is the box [0, 4] x [0, 2] x [0, 1] mm, one trilinear cell
// with constant properties, sampled at 0.5 mm from its corner: 8 x 4 x 2 = 64 voxels, each
// wholly inside, volume 8 mm^3; expected values follow from that and from IEC 61966-2-1.
#include <catch2/catch.hpp>

#include <fstream>
#include <map>
#include <string>

#include "trivox/io/model_file.hpp"
#include "trivox/io/vdb_inspect.hpp"
#include "trivox/job/vdb_job.hpp"
#include "../io/io_test_util.hpp"

using namespace trivox;
using trivox::io::test::TempDir;

namespace {

/// The box with properties r, g, b = 0.5 and the named extra properties = 7.
vmodel::VModel box_model(const std::filesystem::path& file, const std::vector<std::string>& extra) {
  std::string props = "\"r\", \"g\", \"b\"", values = "0.5, 0.5, 0.5";
  for (const auto& e : extra) props += ", \"" + e + "\"", values += ", 7";
  std::string points;
  for (int z : {0, 1})
    for (int y : {0, 2})
      for (int x : {0, 4})
        points += std::string(points.empty() ? "" : ", ") + "[" + std::to_string(x) + ", " + std::to_string(y) + ", " +
                  std::to_string(z) + ", " + values + "]";
  std::ofstream(file) << "{\"trivox\": 1, \"units\": \"mm\", \"properties\": [" << props
                      << "], \"cells\": [{\"name\": \"box\", \"trivariate\": {\"orders\": [2, 2, 2], "
                         "\"knots\": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]], \"points\": ["
                      << points << "]}}]}";
  return io::load_model(file);
}

std::string meta(const std::vector<io::VdbMeta>& m, const std::string& name) {
  for (const auto& e : m)
    if (e.name == name) return e.value;
  return "(none)";
}

}  // namespace

TEST_CASE("vdb job: option names", "[vdb]") {
  job::VdbUnits u{};
  CHECK((job::vdb_units_from_name("m", u) && u == job::VdbUnits::m));
  CHECK((job::vdb_units_from_name("mm", u) && u == job::VdbUnits::mm));
  CHECK_FALSE(job::vdb_units_from_name("cm", u));
  CHECK_FALSE(job::vdb_units_from_name("M", u));
  CHECK(std::string(job::vdb_units_name(job::VdbUnits::m)) == "m");
  job::VdbColorSpace c{};
  CHECK((job::vdb_color_space_from_name("srgb", c) && c == job::VdbColorSpace::srgb));
  CHECK((job::vdb_color_space_from_name("linear", c) && c == job::VdbColorSpace::linear));
  CHECK_FALSE(job::vdb_color_space_from_name("sRGB", c));
  CHECK(std::string(job::vdb_color_space_name(job::VdbColorSpace::linear)) == "linear");
}

TEST_CASE("vdb job: metres, linear colour, reserved names", "[vdb]") {
  TempDir dir("vdb-units");
  const auto model = box_model(dir.path() / "box.json", {"temperature", "heat", "flame", "stiffness"});
  const double grey_linear = 0.2140411404822324424;  // ((0.5 + 0.055) / 1.055)^2.4
  for (const auto units : {job::VdbUnits::mm, job::VdbUnits::m})
    for (const auto space : {job::VdbColorSpace::linear, job::VdbColorSpace::srgb}) {
      const std::string tag = std::string(job::vdb_units_name(units)) + "-" + job::vdb_color_space_name(space);
      INFO(tag);
      job::VdbJobOptions o;
      o.out_dir = dir.path() / tag;
      o.model_file = dir.path() / "box.json";
      o.voxel_mm = 0.5;
      o.units = units;
      o.color_space = space;
      const auto s = job::run_vdb_job(model, o);
      CHECK(s.active_voxels == 64);
      CHECK(s.volume_mm3 == Approx(8.0).epsilon(1e-12));  // the summary stays in mm
      CHECK(s.units == job::vdb_units_name(units));

      const io::VdbReport r = io::inspect_vdb(s.file);
      const double unit = units == job::VdbUnits::m ? 1e-3 : 1.0;  // world units per mm
      CHECK(r.units == job::vdb_units_name(units));
      REQUIRE(r.mm_per_unit);
      CHECK(*r.mm_per_unit == 1.0 / unit);
      REQUIRE(r.volume);
      CHECK(*r.volume == Approx(8.0 * unit * unit * unit).epsilon(1e-9));
      CHECK(meta(r.metadata, "units") == job::vdb_units_name(units));
      CHECK(meta(r.metadata, "color_space") == job::vdb_color_space_name(space));
      CHECK(std::stod(meta(r.metadata, "voxel_size")) == Approx(0.5 * unit).epsilon(1e-12));

      std::map<std::string, const io::VdbGridInfo*> grids;
      for (const auto& g : r.grids) grids[g.name] = &g;
      // Names Blender or Houdini read with a meaning are prefixed; others keep theirs.
      for (const char* n : {"temperature", "heat", "flame"}) {
        CHECK(grids.count(n) == 0);
        REQUIRE(grids.count(std::string("property.") + n) == 1);
        CHECK(meta(grids[std::string("property.") + n]->metadata, "property") == n);
      }
      CHECK(grids.count("stiffness") == 1);
      CHECK(r.grids.size() == 3 + 6 + 4);
      for (const auto& g : r.grids) {
        INFO(g.name);
        CHECK(g.active_voxels == 64);
        for (int d = 0; d < 3; ++d) {
          CHECK(g.voxel_size[static_cast<std::size_t>(d)] == Approx(0.5 * unit).epsilon(1e-12));
          CHECK(g.world_bounds[0][static_cast<std::size_t>(d)] == Approx(0.0).margin(1e-12 * unit));
        }
        CHECK(g.world_bounds[1][0] == Approx(4.0 * unit).epsilon(1e-12));
        CHECK(g.world_bounds[1][1] == Approx(2.0 * unit).epsilon(1e-12));
        CHECK(g.world_bounds[1][2] == Approx(1.0 * unit).epsilon(1e-12));
        CHECK(meta(g.metadata, "units") == job::vdb_units_name(units));
      }
      for (const char* n : {"color", "Cd"}) {
        const auto& g = *grids.at(n);
        CHECK(meta(g.metadata, "color_space") == job::vdb_color_space_name(space));
        const double want = space == job::VdbColorSpace::linear ? grey_linear : 0.5;
        for (int q = 0; q < 3; ++q) {
          CHECK(g.min[static_cast<std::size_t>(q)] == Approx(want).margin(1e-7));
          CHECK(g.max[static_cast<std::size_t>(q)] == Approx(want).margin(1e-7));
        }
      }
    }
}
