// Volumes of the G+Smo reference models (data nobody here wrote): the cube [-1,2]^3 as a unit cube
// and six frustums (27, each frustum (9 + 1 + 3) / 3 = 13/3), and the Fichera corner, seven unit
// cubes (7).
#include <catch2/catch.hpp>

#include <filesystem>

#include "trivox/geom/quadrature.hpp"
#include "trivox/io/model_file.hpp"

using namespace trivox;

namespace {
double total_volume(const vmodel::VModel& m) {
  double v = 0;
  for (const auto& c : m.cells) v += geom::volume(c.volume);
  return v;
}
const std::filesystem::path gismo = std::filesystem::path(TRIVOX_SOURCE_DIR) / "models" / "gismo";
}  // namespace

TEST_CASE("the G+Smo cube has volume 27, its frustums 13/3 each") {
  const auto m = io::load_model(gismo / "cube.xml");
  REQUIRE(m.cells.size() == 7);
  CHECK(total_volume(m) == Approx(27.0).epsilon(1e-14));
  int frustums = 0;
  for (const auto& c : m.cells) frustums += std::abs(geom::volume(c.volume) - 13.0 / 3.0) < 1e-13;
  CHECK(frustums == 6);
}

TEST_CASE("the Fichera corner has volume 7") {
  const auto m = io::load_model(gismo / "fichera.xml");
  REQUIRE(m.cells.size() == 7);
  CHECK(total_volume(m) == Approx(7.0).epsilon(1e-14));
}
