// Palettes and the mapping of properties to material fractions: the default palette and its
// file, one test per kind of malformed palette (each message names the file, the JSON pointer
// and what was expected), and the colour conversion checked against its defining property
// (averaging the ideal primaries with the fractions gives the colour back).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <unistd.h>

#include "../io/io_test_util.hpp"  // error_of, check_message: shared with the io tests
#include "trivox/error.hpp"
#include "trivox/slice/material.hpp"

namespace {

using namespace trivox::slice;
using nlohmann::json;

using trivox::io::test::check_message;
using trivox::io::test::error_of;

/// The message of parsing `j` (dumped) as the palette file "p.json".
std::string palette_error(const json& j) {
  return error_of([&] { parse_palette(j.dump(), "p.json"); });
}

json valid_palette() {
  return {{"trivox_palette", 1},
          {"materials",
           {{{"name", "A"}, {"rgba", {10, 20, 30, 255}}},
            {{"name", "B"}, {"rgba", {40, 50, 60}}},
            {{"name", "C"}, {"rgba", {70, 80, 90, 128}}}}}};
}

/// Averages the ideal colours of C, M, Y, K, W with weights f: the colour side-by-side mixing
/// shows from afar.
std::array<double, 3> mix(const std::array<float, 5>& f) {
  const double ideal[5][3] = {{0, 1, 1}, {1, 0, 1}, {1, 1, 0}, {0, 0, 0}, {1, 1, 1}};
  std::array<double, 3> c{};
  for (int k = 0; k < 5; ++k)
    for (int i = 0; i < 3; ++i) c[i] += f[k] * ideal[k][i];
  return c;
}

std::vector<float> fractions_of(const MaterialMapper& m, std::vector<float> props) {
  REQUIRE(static_cast<int>(props.size()) == m.properties());
  std::vector<float> out(static_cast<std::size_t>(m.materials()), -1.0f);
  m.fractions(props.data(), out.data());
  return out;
}

void check_fractions(const std::vector<float>& got, const std::vector<float>& want) {
  REQUIRE(got.size() == want.size());
  for (std::size_t k = 0; k < got.size(); ++k) {
    INFO("material " << k);
    CHECK(got[k] == Approx(want[k]).margin(1e-6));
  }
}

}  // namespace

TEST_CASE("default palette holds the Voxel Print keys", "[material]") {
  const Palette p = default_palette();
  REQUIRE(p.materials.size() == 6);
  CHECK(p.materials[0] == Material{"VeroCyan-V", {0, 137, 166, 255}});
  CHECK(p.materials[1] == Material{"VeroMagenta-V", {198, 0, 88, 255}});
  CHECK(p.materials[2] == Material{"VeroYellow-V", {240, 197, 0, 255}});
  CHECK(p.materials[3] == Material{"VeroBlack", {26, 26, 29, 255}});
  CHECK(p.materials[4] == Material{"VeroUltraWhite", {255, 255, 255, 255}});
  CHECK(p.materials[5] == Material{"UltraClear", {137, 137, 137, 255}});
  CHECK(p.default_material == p.find("VeroUltraWhite"));
  CHECK(p.find("UltraClear") == 5);
  CHECK(p.find("ultraclear") == -1);
  CHECK(p.find("") == -1);
}

TEST_CASE("palette files: the shipped default equals default_palette, and files round-trip", "[material]") {
  const auto dir = std::filesystem::path(TRIVOX_SOURCE_DIR) / "models" / "palettes";
  CHECK(load_palette(dir / "vero.json") == default_palette());
  CHECK(parse_palette(palette_json(default_palette()), "x") == default_palette());
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    INFO(entry.path());
    const Palette p = load_palette(entry.path());
    CHECK(parse_palette(palette_json(p), "x") == p);
  }
  // Without "rgb_materials" the palette keeps the default Vero names, none of which it has: the
  // file written leaves the key out rather than name materials the palette lacks.
  const Palette own = parse_palette(valid_palette().dump(), "p.json");
  REQUIRE(own.find(ColourMaterials{}.cyan) == -1);
  CHECK(parse_palette(palette_json(own), "x") == own);
  CHECK(palette_json(own).find("rgb_materials") == std::string::npos);
  Palette odd = own;
  odd.rgb_materials.white = "nothing";
  CHECK_THROWS_AS(palette_json(odd), trivox::Error);
}

TEST_CASE("palette parsing: optional fields and defaults", "[material]") {
  Palette p = parse_palette(valid_palette().dump(), "p.json");
  REQUIRE(p.materials.size() == 3);
  CHECK(p.materials[1].rgba == std::array<std::uint8_t, 4>{40, 50, 60, 255});  // [r,g,b]: opaque
  CHECK(p.materials[2].rgba[3] == 128);
  CHECK(p.default_material == 0);
  CHECK(p.rgb_materials == ColourMaterials{});
  CHECK(p.name == "custom");

  json j = valid_palette();
  j["name"] = "three";
  j["description"] = "anything";
  j["default"] = "C";
  j["materials"][0]["description"] = "first";
  j["rgb_materials"] = {{"cyan", "A"}, {"magenta", "B"}, {"yellow", "C"}, {"black", "A"}, {"white", "B"}};
  p = parse_palette(j.dump(), "p.json");
  CHECK(p.name == "three");
  CHECK(p.default_material == 2);
  CHECK(p.rgb_materials == ColourMaterials{"A", "B", "C", "A", "B"});

  // 254 materials is the most; version 1.0 is 1.
  j = {{"trivox_palette", 1.0}, {"materials", json::array()}};
  for (int i = 0; i < 254; ++i) j["materials"].push_back({{"name", std::string(1, 'm').append(std::to_string(i))}, {"rgba", {i, 0, 0, 255}}});
  CHECK(parse_palette(j.dump(), "p.json").materials.size() == 254);
}

TEST_CASE("malformed palettes name the file, the place and what was expected", "[material]") {
  SECTION("syntax") {
    const std::string m = error_of([] { parse_palette("{\n  \"trivox_palette\": 1,\n  \"materials\": [,]\n}", "p.json"); });
    check_message(m, {"p.json", "line 3", "malformed JSON", "expected"});
    check_message(error_of([] { parse_palette("", "p.json"); }), {"p.json", "malformed JSON", "expected"});
    check_message(error_of([] { parse_palette("{\"trivox_palette\": 1e999}", "p.json"); }),
                  {"p.json: line 1, column 20", "number overflow", "expected a finite number"});
  }
  SECTION("top level") {
    check_message(palette_error(json::array()), {"p.json: top level", "found an array of 0", "expected an object"});
    json j = valid_palette();
    j.erase("trivox_palette");
    check_message(palette_error(j), {"p.json: top level", "missing \"trivox_palette\"", "expected 1"});
    j["trivox"] = 1;
    check_message(palette_error(j), {"looks like a model file"});
    j = valid_palette();
    j["trivox_palette"] = 2;
    check_message(palette_error(j), {"p.json: /trivox_palette", "found the number 2", "expected 1"});
    j = valid_palette();
    j["defualt"] = "A";
    check_message(palette_error(j), {"p.json: /defualt", "unknown key \"defualt\"", "expected one of", "default"});
    j = valid_palette();
    j["a/b~\n"] = 1;
    check_message(palette_error(j), {"p.json: /a~1b~0?: unknown key \"a/b~\\n\""});
    j = valid_palette();
    j["name"] = "";
    check_message(palette_error(j), {"p.json: /name", "expected a name of 1 to 64"});
  }
  SECTION("material list") {
    json j = valid_palette();
    j.erase("materials");
    check_message(palette_error(j), {"p.json: top level", "missing \"materials\"", "expected an array of 1 to 254"});
    j["materials"] = json::array();
    check_message(palette_error(j), {"p.json: /materials", "found an array of 0", "expected an array of 1 to 254"});
    j["materials"] = {{"name", "A"}};
    check_message(palette_error(j), {"p.json: /materials", "found an object", "expected an array"});
    j["materials"] = json::array();
    for (int i = 0; i < 255; ++i) j["materials"].push_back({{"name", std::string(1, 'm').append(std::to_string(i))}, {"rgba", {i, 0, 0, 255}}});
    check_message(palette_error(j), {"p.json: /materials", "found an array of 255", "1 to 254"});
  }
  SECTION("names") {
    json j = valid_palette();
    j["materials"][1] = "B";
    check_message(palette_error(j), {"p.json: /materials/1", "found the string \"B\"", "expected an object"});
    j = valid_palette();
    j["materials"][1].erase("name");
    check_message(palette_error(j), {"p.json: /materials/1", "missing \"name\"", "expected a name"});
    for (const json& bad : {json(""), json(7), json(" A"), json("A<B"), json(std::string(65, 'a')), json("x\ny")}) {
      j = valid_palette();
      j["materials"][1]["name"] = bad;
      check_message(palette_error(j), {"p.json: /materials/1/name", "found", "expected a name of 1 to 64 characters"});
    }
    j = valid_palette();
    j["materials"][2]["name"] = "A";
    check_message(palette_error(j),
                  {"p.json: /materials/2/name", "found \"A\"", "/materials/0", "expected unique material names"});
    j = valid_palette();
    j["materials"][0]["name"] = "g";
    check_message(palette_error(j), {"p.json: /materials/0/name", "expected a name other than r, g and b"});
    j = valid_palette();
    j["materials"][0]["colour"] = "red";
    check_message(palette_error(j), {"p.json: /materials/0/colour", "unknown key", "expected one of name, rgba"});
  }
  SECTION("colours") {
    json j = valid_palette();
    j["materials"][2].erase("rgba");
    check_message(palette_error(j), {"p.json: /materials/2", "missing \"rgba\"", "expected an array [r, g, b, a]"});
    for (const json& bad : {json("red"), json({1, 2}), json({1, 2, 3, 4, 5})}) {
      j = valid_palette();
      j["materials"][2]["rgba"] = bad;
      check_message(palette_error(j), {"p.json: /materials/2/rgba", "found", "expected an array [r, g, b, a]"});
    }
    j = valid_palette();
    j["materials"][2]["rgba"] = {0, 256, 0, 255};
    check_message(palette_error(j), {"p.json: /materials/2/rgba/1", "found the number 256", "expected an integer 0..255"});
    j["materials"][2]["rgba"] = {0, -1, 0, 255};
    check_message(palette_error(j), {"p.json: /materials/2/rgba/1", "found the number -1", "expected an integer 0..255"});
    j["materials"][2]["rgba"] = {0, 1.5, 0, 255};
    check_message(palette_error(j), {"p.json: /materials/2/rgba/1", "found the number 1.5", "expected an integer"});
    j["materials"][2]["rgba"] = {0, "1", 0, 255};
    check_message(palette_error(j), {"p.json: /materials/2/rgba/1", "found the string \"1\"", "expected an integer"});
    j["materials"][2]["rgba"] = {0, 0, 0, 0};
    check_message(palette_error(j), {"p.json: /materials/2/rgba/3", "found the number 0", "expected an integer 1..255",
                                     "alpha 0 is void"});
    j["materials"][2]["rgba"] = {10, 20, 30};
    check_message(palette_error(j), {"p.json: /materials/2/rgba", "found [10,20,30,255], the colour of /materials/0 (A)",
                                     "expected a colour unique to each material"});
  }
  SECTION("default and colour materials") {
    json j = valid_palette();
    j["default"] = "D";
    check_message(palette_error(j), {"p.json: /default", "found \"D\"", "expected the name of a palette material (A, B, C)"});
    j["default"] = 0;
    check_message(palette_error(j), {"p.json: /default", "found the number 0", "expected a name"});
    j = valid_palette();
    j["rgb_materials"] = {{"cyan", "A"}, {"magenta", "B"}, {"yellow", "C"}, {"black", "A"}};
    check_message(palette_error(j), {"p.json: /rgb_materials", "missing \"white\"", "expected an object naming"});
    j["rgb_materials"]["white"] = "VeroUltraWhite";
    check_message(palette_error(j), {"p.json: /rgb_materials/white", "found \"VeroUltraWhite\"",
                                     "expected the name of a palette material"});
    j["rgb_materials"]["white"] = "A";
    j["rgb_materials"]["grey"] = "A";
    check_message(palette_error(j), {"p.json: /rgb_materials/grey", "unknown key", "expected one of cyan"});
    j["rgb_materials"] = {"A"};
    check_message(palette_error(j), {"p.json: /rgb_materials", "found an array of 1", "expected an object"});
  }
  SECTION("files") {
    const auto missing = std::filesystem::temp_directory_path() / "trivox-no-such-palette.json";
    check_message(error_of([&] { load_palette(missing); }), {missing.string(), "no such file", "expected a readable"});
    check_message(error_of([&] { load_palette(std::filesystem::temp_directory_path()); }),
                  {"is a folder", "expected a palette file"});
    const auto file = std::filesystem::temp_directory_path() / ("trivox-palette-" + std::to_string(::getpid()) + ".json");
    {
      std::ofstream(file) << "{\"trivox_palette\": 1, \"materials\": [{\"name\": \"A\", \"rgba\": [1,2,3,300]}]}";
    }
    check_message(error_of([&] { load_palette(file); }), {file.string() + ": /materials/0/rgba/3", "found the number 300"});
    std::filesystem::remove(file);
  }
}

TEST_CASE("colour conversion: named colours", "[material]") {
  using F = std::array<float, 5>;  // C M Y K W
  auto check = [](float r, float g, float b, F want) {
    INFO("rgb " << r << " " << g << " " << b);
    const F got = rgb_to_cmykw(r, g, b);
    for (int k = 0; k < 5; ++k) CHECK(got[k] == Approx(want[k]).margin(1e-7));
  };
  check(1, 1, 1, {0, 0, 0, 0, 1});        // white -> white
  check(0, 0, 0, {0, 0, 0, 1, 0});        // black -> black
  check(0, 1, 1, {1, 0, 0, 0, 0});        // cyan
  check(1, 0, 1, {0, 1, 0, 0, 0});        // magenta
  check(1, 1, 0, {0, 0, 1, 0, 0});        // yellow
  check(0.5, 0.5, 0.5, {0, 0, 0, 0.5, 0.5});  // grey: half black, half white
  check(0.2f, 0.2f, 0.2f, {0, 0, 0, 0.8f, 0.2f});
  check(0, 0.5, 0.5, {0.5, 0, 0, 0.5, 0});  // dark cyan
  check(0.5, 1, 1, {0.5, 0, 0, 0, 0.5});    // light cyan
  // Red is out of reach of side-by-side mixing (W would be -1): magenta and yellow halves.
  check(1, 0, 0, {0, 0.5, 0.5, 0, 0});
  // Out-of-range and NaN inputs clamp.
  check(2, 7, 1.5, {0, 0, 0, 0, 1});
  check(-1, std::nanf(""), -0.0f, {0, 0, 0, 1, 0});
}

TEST_CASE("colour conversion: fractions are a distribution, and exact wherever mixing can reach", "[material]") {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<float> u(-0.2f, 1.2f);
  int reachable = 0;
  for (int i = 0; i < 20000; ++i) {
    const float r = u(rng), g = u(rng), b = u(rng);
    const auto f = rgb_to_cmykw(r, g, b);
    double sum = 0;
    for (float v : f) {
      CHECK(v >= 0.0f);
      CHECK(v <= 1.0f);
      sum += v;
    }
    REQUIRE(sum == Approx(1.0).margin(1e-6));
    // Reachable colours: the largest channel at most the sum of the other two (W >= 0).
    const float cr = std::clamp(r, 0.0f, 1.0f), cg = std::clamp(g, 0.0f, 1.0f), cb = std::clamp(b, 0.0f, 1.0f);
    const float mx = std::max({cr, cg, cb});
    if (cr + cg + cb - 2 * mx >= 0) {
      ++reachable;
      const auto c = mix(f);
      REQUIRE(c[0] == Approx(cr).margin(1e-6));
      REQUIRE(c[1] == Approx(cg).margin(1e-6));
      REQUIRE(c[2] == Approx(cb).margin(1e-6));
      REQUIRE(f[3] == Approx(1 - mx).margin(1e-6));  // maximal black
    }
  }
  CHECK(reachable > 5000);
}

TEST_CASE("material mapper: rgb properties drive the five colour materials", "[material]") {
  const Palette p = default_palette();  // C M Y K W Clear
  const MaterialMapper m(p, {"r", "density", "g", "b"});
  CHECK(m.materials() == 6);
  CHECK(m.properties() == 4);
  CHECK_FALSE(m.constant());
  check_fractions(fractions_of(m, {1, 0.3f, 1, 1}), {0, 0, 0, 0, 1, 0});
  check_fractions(fractions_of(m, {0, 0.3f, 0, 0}), {0, 0, 0, 1, 0, 0});
  check_fractions(fractions_of(m, {0, 0.3f, 1, 1}), {1, 0, 0, 0, 0, 0});
  check_fractions(fractions_of(m, {0.5f, 0.3f, 0.5f, 0.5f}), {0, 0, 0, 0.5f, 0.5f, 0});
  check_message(m.describe(), {"r,g,b -> VeroCyan-V/VeroMagenta-V/VeroYellow-V/VeroBlack/VeroUltraWhite",
                               "ignored: density", "default VeroUltraWhite"});

  // Custom colour materials, in another order.
  Palette q;
  q.materials = {{"W", {1, 1, 1, 255}}, {"K", {2, 2, 2, 255}}, {"Y", {3, 3, 3, 255}}, {"M", {4, 4, 4, 255}}, {"C", {5, 5, 5, 255}}};
  q.rgb_materials = {"C", "M", "Y", "K", "W"};
  const MaterialMapper mq(q, {"b", "g", "r"});
  check_fractions(fractions_of(mq, {0, 1, 1}), {0, 0, 1, 0, 0});  // yellow
  check_fractions(fractions_of(mq, {0.5f, 1, 0.5f}), {0, 0, 0.5f, 0, 0.5f});  // light green: C .5, Y .5
}

TEST_CASE("material mapper: material properties are fractions, clamped and normalised", "[material]") {
  const Palette p = default_palette();
  const MaterialMapper m(p, {"UltraClear", "temperature", "VeroBlack"});
  CHECK(m.describe() == "UltraClear -> UltraClear; VeroBlack -> VeroBlack (fractions); default VeroUltraWhite; ignored: temperature");
  check_fractions(fractions_of(m, {0.25f, 99, 0.25f}), {0, 0, 0, 0.5f, 0, 0.5f});
  check_fractions(fractions_of(m, {3, 99, 1}), {0, 0, 0, 0.25f, 0, 0.75f});
  check_fractions(fractions_of(m, {-2, 99, 0.1f}), {0, 0, 0, 1, 0, 0});         // negative -> 0
  check_fractions(fractions_of(m, {0, 99, 0}), {0, 0, 0, 0, 1, 0});             // nothing -> default
  check_fractions(fractions_of(m, {-1, 99, -1}), {0, 0, 0, 0, 1, 0});
  check_fractions(fractions_of(m, {std::nanf(""), 99, 0.5f}), {0, 0, 0, 1, 0, 0});  // NaN -> 0
  check_fractions(fractions_of(m, {INFINITY, 99, 1}), {0, 0, 0, 0, 0, 1});

  // Batch form equals the single form.
  const std::vector<float> props = {0.25f, 1, 0.75f, 0, 0, 0, 2, 0, -1};
  std::vector<float> batch(18);
  m.fractions(props.data(), 3, batch.data());
  for (int v = 0; v < 3; ++v) {
    const auto one = fractions_of(m, {props[3 * v], props[3 * v + 1], props[3 * v + 2]});
    for (int k = 0; k < 6; ++k) CHECK(batch[6 * v + k] == one[k]);
  }
}

TEST_CASE("material mapper: explicit fractions first, the colour fills the rest", "[material]") {
  const MaterialMapper m(default_palette(), {"r", "g", "b", "UltraClear", "VeroCyan-V"});
  // 30 % clear, the remaining 70 % grey 0.5: 35 % black, 35 % white.
  check_fractions(fractions_of(m, {0.5f, 0.5f, 0.5f, 0.3f, 0}), {0, 0, 0, 0.35f, 0.35f, 0.3f});
  // Explicit cyan adds to the colour's cyan.
  check_fractions(fractions_of(m, {0, 1, 1, 0, 0.5f}), {1, 0, 0, 0, 0, 0});
  check_fractions(fractions_of(m, {1, 1, 1, 0, 0.5f}), {0.5f, 0, 0, 0, 0.5f, 0});
  // Explicit fractions summing to 1 or more leave nothing to the colour.
  check_fractions(fractions_of(m, {0, 0, 0, 2, 2}), {0.5f, 0, 0, 0, 0, 0.5f});
  check_fractions(fractions_of(m, {0, 0, 0, 1, 0}), {0, 0, 0, 0, 0, 1});
}

TEST_CASE("material mapper: models without usable properties print the default material", "[material]") {
  Palette p = default_palette();
  for (const std::vector<std::string>& props :
       {std::vector<std::string>{}, {"density"}, {"r"}, {"r", "g"}, {"R", "G", "B"}}) {
    const MaterialMapper m(p, props);
    CHECK(m.constant());
    std::vector<float> values(props.size(), 0.7f);
    check_fractions(fractions_of(m, values), {0, 0, 0, 0, 1, 0});
    CHECK_THAT(m.describe(), Catch::StartsWith("no material properties: every voxel prints VeroUltraWhite"));
  }
  CHECK(MaterialMapper(p, {"r", "g"}).describe().ends_with("ignored: r,g"));
  p.default_material = 5;
  check_fractions(fractions_of(MaterialMapper(p, {}), {}), {0, 0, 0, 0, 0, 1});
}

TEST_CASE("material mapper: a palette lacking the colour materials is refused for rgb models", "[material]") {
  Palette p = default_palette();
  p.name = "no-black";
  p.materials.erase(p.materials.begin() + 3);  // VeroBlack
  p.default_material = 3;
  CHECK_NOTHROW(MaterialMapper(p, {"UltraClear"}));  // colour not needed
  check_message(error_of([&] { MaterialMapper(p, {"r", "g", "b"}); }),
                {"palette \"no-black\"", "r, g, b need the materials", "lacks VeroBlack", "expected a palette holding them",
                 "rgb_materials"});
  // With the palette's file as its source, the message starts with the file (the slice and VDB jobs).
  const std::string with_file = error_of([&] { MaterialMapper(p, {"r", "g", "b"}, "palettes/no-black.json"); });
  CHECK(with_file.starts_with("palettes/no-black.json: palette \"no-black\""));
  CHECK_NOTHROW(MaterialMapper(p, {"UltraClear"}, "palettes/no-black.json"));
  p.default_material = 7;
  check_message(error_of([&] { MaterialMapper(p, {}); }), {"default material index 7", "expected"});
  check_message(error_of([&] { MaterialMapper(Palette{}, {}); }), {"0 materials", "expected 1 to 254"});
}
