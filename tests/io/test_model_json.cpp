// The JSON model format: reading valid files, exact round trips, and one test per kind of
// malformed input, each checking that the message names the file, the JSON pointer and what
// was expected.
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>

#include "io_test_util.hpp"
#include "trivox/io/model_json.hpp"

namespace {

using nlohmann::json;
using trivox::io::read_model_json;
using trivox::io::write_model_json;
using trivox::io::test::check_message;
using trivox::io::test::error_of;
using namespace trivox::spline;
using trivox::vmodel::VModel;

/// Trilinear cell on [0,1]^3 with properties (r, g, b) = (i, j, k) at control point (i, j, k).
json unit_block() {
  json points = json::array();
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) points.push_back({i, j, k, i, j, k});
  return {{"orders", {2, 2, 2}},
          {"knots", {{0, 0, 1, 1}, {0, 0, 1, 1}, {0, 0, 1, 1}}},
          {"points", points},
          {"weights", nullptr}};
}

/// A 3 x 3 x 2 rational cell (orders 3, 2, 2; an interior knot in v).
json rational_block() {
  json points = json::array(), weights = json::array();
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        points.push_back({i + 2.0, j * 0.5, k, 0.25, 0.5, 0.75});
        weights.push_back(i == 1 ? 0.5 : 1.0);
      }
  return {{"orders", {3, 2, 2}},
          {"knots", {{0, 0, 0, 1, 1, 1}, {0, 0, 0.5, 1, 1}, {0, 0, 1, 1}}},
          {"points", points},
          {"weights", weights}};
}

json unit_square() {
  return {{"orders", {2, 2}},
          {"knots", {{0, 0, 1, 1}, {0, 0, 1, 1}}},
          {"points", {{0, 0, 5, 1, 1, 1}, {1, 0, 5, 1, 1, 1}, {0, 1, 5, 1, 1, 1}, {1, 1, 5, 1, 1, 1}}}};
}

json valid_model() {
  return {{"trivox", 1},
          {"units", "mm"},
          {"properties", {"r", "g", "b"}},
          {"cells",
           {{{"name", "block"}, {"trivariate", unit_block()}},
            {{"name", "arch"}, {"trivariate", rational_block()}}}},
          {"surfaces", {{{"name", "lid"}, {"surface", unit_square()}}}},
          {"operations", json::array()}};
}

VModel read(const json& j) { return read_model_json(j.dump(), "model.json"); }

std::string error_for(const json& j) {
  return error_of([&] { read(j); });
}

/// Every double of a model, in a fixed order, for bitwise comparison.
template <int P>
void append_doubles(const TensorSpline<P>& s, std::vector<double>& out) {
  for (int d = 0; d < P; ++d)
    out.insert(out.end(), s.knots(d).knots().begin(), s.knots(d).knots().end());
  out.insert(out.end(), s.points().begin(), s.points().end());
  out.insert(out.end(), s.weights().begin(), s.weights().end());
}

std::vector<std::uint64_t> bits(const VModel& m) {
  std::vector<double> v;
  for (const auto& c : m.cells) append_doubles(c.volume, v);
  for (const auto& s : m.surfaces) append_doubles(s.surface, v);
  std::vector<std::uint64_t> out;
  for (double x : v) out.push_back(std::bit_cast<std::uint64_t>(x));
  return out;
}

/// A finite double with arbitrary bits: every exponent and mantissa pattern is exercised.
double random_finite(std::mt19937_64& rng) {
  while (true) {
    const double v = std::bit_cast<double>(rng());
    if (std::isfinite(v)) return v;
  }
}

/// A model whose values are hard to print: random bit patterns, -0, subnormals, extremes.
VModel awkward_model() {
  std::mt19937_64 rng(20240611);
  VModel m;
  m.units = "in";
  m.properties = {"density", "r\"quoted\"", "\xC3\xA9t\xC3\xA9"};  // UTF-8 "été"
  const double specials[] = {-0.0, 5e-324, 2.2250738585072014e-308, 1.7976931348623157e308,
                             -1.7976931348623157e308, 0.1, 1.0 / 3.0, 1e-7, 123456789.0};
  std::vector<double> points;
  for (int i = 0; i < 3 * 2 * 2 * 6; ++i)
    points.push_back(i < 9 ? specials[i] : random_finite(rng));
  KnotVector u(3, {-0.0, -0.0, -0.0, 0.1, 0.1, 1.0 / 3.0});  // 3 functions, not clamped at 1/3
  KnotVector v(2, {0, 0, 1e-300, 1e-300});
  KnotVector w(1, {-2.5, 1.0 / 7.0, 3});
  std::vector<double> weights;
  for (int i = 0; i < 12; ++i) weights.push_back(std::ldexp(1.0 + i / 13.0, i - 6));
  m.cells.push_back({"cell \\ with / odd \"name\"", Trivariate({u, v, w}, 6, points, weights)});
  m.cells.push_back({"plain", Trivariate({KnotVector::bezier(2), KnotVector::bezier(2),
                                          KnotVector::bezier(2)},
                                         6, std::vector<double>(8 * 6, 0.5))});
  std::vector<double> sp;
  for (int i = 0; i < 4 * 6; ++i) sp.push_back(random_finite(rng));
  m.surfaces.push_back({"s", Surface({KnotVector::bezier(2), KnotVector::bezier(2)}, 6, sp,
                                     {1, 2, 3, 1e-300})});
  return m;
}

}  // namespace

// --------------------------------------------------------------------------------------------
// Valid input

TEST_CASE("a model file is read with its cells, surfaces and properties", "[io][json]") {
  const VModel m = read(valid_model());
  CHECK(m.units == "mm");
  CHECK(m.properties == std::vector<std::string>{"r", "g", "b"});
  REQUIRE(m.cells.size() == 2);
  REQUIRE(m.surfaces.size() == 1);
  CHECK(m.cells[0].name == "block");
  CHECK(m.cells[1].name == "arch");
  CHECK(m.surfaces[0].name == "lid");

  const Trivariate& block = m.cells[0].volume;
  CHECK(block.dim() == 6);
  CHECK(block.orders() == Trivariate::Index{2, 2, 2});
  CHECK_FALSE(block.rational());
  // Row i + 2 (j + 2 k) is (i, j, k, i, j, k): u varies fastest.
  const auto p6 = block.point(6);  // i = 0, j = 1, k = 1
  CHECK(std::vector<double>(p6.begin(), p6.end()) == std::vector<double>{0, 1, 1, 0, 1, 1});

  const Trivariate& arch = m.cells[1].volume;
  CHECK(arch.counts() == Trivariate::Index{3, 3, 2});
  REQUIRE(arch.rational());
  CHECK(arch.weights()[1] == 0.5);
  CHECK(arch.knots(1).knots() == std::vector<double>{0, 0, 0.5, 1, 1});
  CHECK(m.surfaces[0].surface.point(3)[2] == 5.0);
}

TEST_CASE("optional keys take their defaults and unknown keys are ignored", "[io][json]") {
  json j = {{"trivox", 1}, {"cells", {{{"name", "c"}, {"trivariate", unit_block()}}}}};
  j["cells"][0]["trivariate"].erase("weights");
  for (auto& p : j["cells"][0]["trivariate"]["points"]) p = {p[0], p[1], p[2]};
  j["generator"] = "someone else's tool";
  j["cells"][0]["colour"] = "blue";
  const VModel m = read(j);
  CHECK(m.units == "mm");
  CHECK(m.properties.empty());
  CHECK(m.cells.at(0).volume.dim() == 3);
  CHECK(m.surfaces.empty());
}

TEST_CASE("orders written as doubles with integral values are accepted", "[io][json]") {
  json j = valid_model();
  j["cells"][0]["trivariate"]["orders"] = {2.0, 2.0, 2.0};
  CHECK(read(j).cells[0].volume.orders() == Trivariate::Index{2, 2, 2});
}

// --------------------------------------------------------------------------------------------
// Writing and round trips

TEST_CASE("write then read gives the same model, bit for bit", "[io][json]") {
  const VModel m = awkward_model();
  const std::string text = write_model_json(m);
  const VModel back = read_model_json(text, "awkward.json");
  CHECK(back == m);
  CHECK(bits(back) == bits(m));  // == treats -0.0 and 0.0 as equal; the bits do not
  CHECK(std::signbit(back.cells[0].volume.points()[0]));
  // Writing is deterministic and stable under a round trip.
  CHECK(write_model_json(back) == text);
}

TEST_CASE("the valid example survives a round trip", "[io][json]") {
  const VModel m = read(valid_model());
  CHECK(read_model_json(write_model_json(m), "again.json") == m);
}

TEST_CASE("the written file is format version 1 with one control point per line", "[io][json]") {
  VModel m = read(valid_model());
  m.surfaces.clear();
  const std::string text = write_model_json(m);
  const json j = json::parse(text);
  CHECK(j["trivox"] == 1);
  CHECK(j["units"] == "mm");
  CHECK(j["operations"] == json::array());
  CHECK_FALSE(j.contains("surfaces"));  // written only when there are some
  CHECK(j["cells"][0]["trivariate"]["weights"].is_null());
  CHECK(j["cells"][1]["trivariate"]["weights"].size() == 18);
  // Control point 7 of the block, (1, 1, 1, 1, 1, 1), sits alone on its line.
  CHECK_THAT(text, Catch::Contains("\n          [1.0, 1.0, 1.0, 1.0, 1.0, 1.0]"));
  const auto lines = std::count(text.begin(), text.end(), '\n');
  CHECK(lines > 8 + 18);
  CHECK(lines < 100);
}

TEST_CASE("models that could not be read back are not written", "[io][json]") {
  VModel m = read(valid_model());
  SECTION("no cells and no surfaces") {
    m.cells.clear();
    m.surfaces.clear();
    check_message(error_of([&] { (void)write_model_json(m); }), {"no cells", "expected"});
  }
  SECTION("a cell with the wrong number of coordinates") {
    m.properties.pop_back();
    check_message(error_of([&] { (void)write_model_json(m); }),
                  {"\"block\"", "6 coordinates", "expected 5 (xyz + 2 properties)"});
  }
  SECTION("repeated names") {
    m.surfaces[0].name = "block";
    check_message(error_of([&] { (void)write_model_json(m); }), {"\"block\"", "expected unique"});
  }
  SECTION("a non-finite coordinate") {
    m.cells[1].volume.points()[4] = std::numeric_limits<double>::quiet_NaN();
    check_message(error_of([&] { (void)write_model_json(m); }), {"\"arch\"", "non-finite", "expected"});
  }
  SECTION("unknown units") {
    m.units = "furlong";
    check_message(error_of([&] { (void)write_model_json(m); }), {"furlong", "expected"});
  }
}

// --------------------------------------------------------------------------------------------
// Malformed input: one case each

TEST_CASE("malformed JSON is reported with its line and column", "[io][json][bad]") {
  const std::string text = "{\n  \"trivox\": 1,\n  \"cells\": [1, 2 x]\n}\n";
  check_message(error_of([&] { read_model_json(text, "model.json"); }),
                {"model.json: line 3, column 18: malformed JSON", "expected ']'"});
  check_message(error_of([&] { read_model_json("", "empty.json"); }),
                {"empty.json: line 1, column 1", "unexpected end of input", "expected"});
  check_message(error_of([&] { read_model_json("{\"trivox\": 1} {}", "two.json"); }),
                {"two.json: line 1, column 15", "expected end of input"});
  const std::string bad_utf8 = error_of([&] { read_model_json("{\"a\": \"\xff\"}", "utf.json"); });
  check_message(bad_utf8, {"utf.json: line 1", "UTF-8", "expected"});
  CHECK(std::none_of(bad_utf8.begin(), bad_utf8.end(), [](char c) { return c & 0x80; }));
  // An unterminated string must not copy the rest of the file into the message.
  const std::string open = "{\"trivox\": 1, \"units\": \"" + std::string(100000, 'a');
  const std::string unterminated = error_of([&] { read_model_json(open, "open.json"); });
  check_message(unterminated, {"open.json: line 1", "expected"});
  CHECK(unterminated.size() < 300);
}

TEST_CASE("numbers too large for a double are reported with their position", "[io][json][bad]") {
  const std::string text = "{\"trivox\": 1,\n \"units\": \"mm\",\n \"x\": [0, 1e999]}";
  check_message(error_of([&] { read_model_json(text, "big.json"); }),
                {"big.json: line 3, column 11", "1e999", "expected a finite number"});
}

TEST_CASE("the top level must be a version-1 trivox object", "[io][json][bad]") {
  check_message(error_of([] { read_model_json("[1, 2]", "a.json"); }),
                {"a.json: top level: found an array of 2; expected a trivox model object"});
  json j = valid_model();
  j.erase("trivox");
  check_message(error_for(j), {"model.json: top level: missing \"trivox\"", "expected \"trivox\": 1"});
  j["trivox"] = 2;
  check_message(error_for(j), {"model.json: /trivox: format version 2; expected 1"});
  j["trivox"] = "1";
  check_message(error_for(j), {"model.json: /trivox: found the string \"1\"; expected the format version 1"});
}

TEST_CASE("a scene is recognised and sent to trivox build", "[io][json][bad]") {
  json j = valid_model();
  j["cells"][1] = {{"name", "ball"},
                   {"primitive", {{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 10}}},
                   {"field", {{"constant", {1, 0, 0}}}}};
  check_message(error_for(j), {"model.json: /cells/1/primitive: this is a scene", "expected a model",
                               "trivox build"});
  j = valid_model();
  j["operations"] = {{{"op", "union"}, {"a", "block"}, {"b", "arch"}}};
  check_message(error_for(j), {"model.json: /operations: this is a scene", "expected", "trivox build"});
  j["operations"] = "none";
  check_message(error_for(j), {"/operations: found the string \"none\"; expected an array"});
}

TEST_CASE("units must be a known unit name", "[io][json][bad]") {
  json j = valid_model();
  j["units"] = "parsec";
  check_message(error_for(j), {"model.json: /units: unknown units \"parsec\"; expected one of"});
  j["units"] = 1;
  check_message(error_for(j), {"model.json: /units: found the number 1; expected one of"});
}

TEST_CASE("properties must be unique non-empty strings", "[io][json][bad]") {
  json j = valid_model();
  j["properties"] = "rgb";
  check_message(error_for(j), {"model.json: /properties: found the string \"rgb\"; expected an array"});
  j["properties"] = {"r", 2, "b"};
  check_message(error_for(j), {"model.json: /properties/1: found the number 2; expected a unique non-empty property name"});
  j["properties"] = {"r", "g", "r"};
  check_message(error_for(j), {"model.json: /properties/2: \"r\" repeats /properties/0; expected"});
  j["properties"] = {"r", "", "b"};
  check_message(error_for(j), {"model.json: /properties/1: empty name; expected"});
}

TEST_CASE("cells must be an array of named objects", "[io][json][bad]") {
  json j = valid_model();
  j["cells"] = {{"name", "x"}};  // an object, not an array of objects
  check_message(error_for(j), {"model.json: /cells: found an object; expected an array"});
  j = valid_model();
  j["cells"][1] = 7;
  check_message(error_for(j), {"model.json: /cells/1: found the number 7; expected an object"});
}

TEST_CASE("cell names must be present, non-empty and unique", "[io][json][bad]") {
  json j = valid_model();
  j["cells"][1].erase("name");
  check_message(error_for(j), {"model.json: /cells/1: missing \"name\"; expected a unique non-empty name"});
  j["cells"][1]["name"] = "";
  check_message(error_for(j), {"model.json: /cells/1/name: empty name; expected"});
  j["cells"][1]["name"] = nullptr;
  check_message(error_for(j), {"model.json: /cells/1/name: found null; expected a unique non-empty name"});
  j["cells"][1]["name"] = "block";
  check_message(error_for(j), {"model.json: /cells/1/name: \"block\" is also the name of /cells/0; expected"});
  j["cells"][1]["name"] = "arch";
  j["surfaces"][0]["name"] = "arch";
  check_message(error_for(j), {"model.json: /surfaces/0/name: \"arch\" is also the name of /cells/1; expected"});
}

TEST_CASE("a cell needs a trivariate object", "[io][json][bad]") {
  json j = valid_model();
  j["cells"][0].erase("trivariate");
  check_message(error_for(j), {"model.json: /cells/0: missing \"trivariate\"; expected {\"name\", \"trivariate\"}"});
  j["cells"][0]["trivariate"] = {1, 2, 3};
  check_message(error_for(j), {"model.json: /cells/0/trivariate: found an array of 3; expected a trivariate"});
}

TEST_CASE("orders: three integers of at least 1", "[io][json][bad]") {
  json j = valid_model();
  auto& t = j["cells"][0]["trivariate"];
  t.erase("orders");
  check_message(error_for(j), {"model.json: /cells/0/trivariate: missing \"orders\"; expected"});
  t["orders"] = {2, 2};
  check_message(error_for(j), {"model.json: /cells/0/trivariate/orders: 2 orders; expected 3 orders"});
  t["orders"] = {2, 0, 2};
  check_message(error_for(j), {"model.json: /cells/0/trivariate/orders/1: found the number 0; expected an integer order (degree + 1) of at least 1"});
  t["orders"] = {2, 2, 1.5};
  check_message(error_for(j), {"/cells/0/trivariate/orders/2: found the number 1.5; expected an integer order"});
  t["orders"] = {2, "2", 2};
  check_message(error_for(j), {"/cells/0/trivariate/orders/1: found the string \"2\"; expected"});
  t["orders"] = {2, 2, 1e300};  // above the order limit (docs/limits.md), refused as such
  check_message(error_for(j), {"/cells/0/trivariate/orders/2: 1e+300; expected an order of at most 32 (limit max_order"});
  t["orders"] = {2, 2, 2000000000};  // a huge order must give a message, not an overflow, whatever the limit
  trivox::Limits raised;
  raised.max_order = 1000000000000000000;
  check_message(error_of([&] { read_model_json(j.dump(), "model.json", raised); }),
                {"/cells/0/trivariate/knots/2: 4 knots for order 2000000000; expected at least 4000000000"});
}

TEST_CASE("knots: one non-decreasing vector per direction, long enough", "[io][json][bad]") {
  json j = valid_model();
  auto& k = j["cells"][1]["trivariate"]["knots"];
  k[1] = {0, 0, 0.5, 1, 0.9};
  check_message(error_for(j), {"model.json: /cells/1/trivariate/knots/1/4: knot 0.9 is less than knot 3 (1.0); expected non-decreasing knots"});
  k = {{0, 0, 0, 1, 1, 1}, {0, 0, 0.5, 1, 1}};
  check_message(error_for(j), {"model.json: /cells/1/trivariate/knots: 2 knot vectors; expected 3"});
  k = {{0, 0, 0, 1, 1, 1}, {0, 0, 0.5, 1, 1}, {0, 0, 1}};
  check_message(error_for(j), {"model.json: /cells/1/trivariate/knots/2: 3 knots for order 2; expected at least 4"});
  k = {{0, 0, 0, 1, 1, 1}, {0, 0, 0.5, 1, 1}, {0, 0, "1", 1}};
  check_message(error_for(j), {"model.json: /cells/1/trivariate/knots/2/2: found the string \"1\"; expected a number"});
  k = {{0, 0, 0, 1, 1, 1}, {0, 0, 0.5, 1, 1}, "0 0 1 1"};
  check_message(error_for(j), {"model.json: /cells/1/trivariate/knots/2: found the string \"0 0 1 1\"; expected an array of knots"});
}

TEST_CASE("knot vector errors from the spline layer are placed in the file", "[io][json][bad]") {
  json j = valid_model();
  auto& k = j["cells"][1]["trivariate"]["knots"];
  k[2] = {1, 1, 1, 1};  // empty domain
  check_message(error_for(j), {"model.json: /cells/1/trivariate/knots/2: empty domain", "expected"});
  k[2] = {0, 0, 1, 1};
  k[0] = {0, 0, 0, 0, 0.5, 1, 1, 1};  // 0 repeated 4 times at order 3
  check_message(error_for(j), {"model.json: /cells/1/trivariate/knots/0: knot value 0", "expected multiplicity <= order"});
}

TEST_CASE("points: the right number of rows of the right length", "[io][json][bad]") {
  json j = valid_model();
  auto& pts = j["cells"][0]["trivariate"]["points"];
  pts[7] = {1, 1, 1, 1, 1};
  check_message(error_for(j), {"model.json: /cells/0/trivariate/points/7: 5 coordinates; expected 6 (xyz + 3 properties)"});
  pts[7] = {1, 1, 1, 1, 1, "1"};
  check_message(error_for(j), {"model.json: /cells/0/trivariate/points/7/5: found the string \"1\"; expected a number"});
  pts[7] = {1, 1, 1, 1, 1, nullptr};
  check_message(error_for(j), {"model.json: /cells/0/trivariate/points/7/5: found null; expected a number"});
  pts[7] = 1;
  check_message(error_for(j), {"model.json: /cells/0/trivariate/points/7: found the number 1; expected a control point: an array of 6 (xyz + 3 properties) numbers"});
  pts.erase(7);
  check_message(error_for(j), {"model.json: /cells/0/trivariate/points: 7 control points; expected 8 (2 x 2 x 2, from the knot vectors and orders)"});
  j["cells"][0]["trivariate"].erase("points");
  check_message(error_for(j), {"model.json: /cells/0/trivariate: missing \"points\"; expected"});
}

TEST_CASE("weights: null, or one positive number per control point", "[io][json][bad]") {
  json j = valid_model();
  auto& w = j["cells"][1]["trivariate"]["weights"];
  w[4] = 0;
  check_message(error_for(j), {"model.json: /cells/1/trivariate/weights/4: weight 0.0; expected a positive weight"});
  w[4] = -1.5;
  check_message(error_for(j), {"model.json: /cells/1/trivariate/weights/4: weight -1.5; expected a positive weight"});
  w.erase(4);
  check_message(error_for(j), {"model.json: /cells/1/trivariate/weights: 17 weights; expected 18 (one per control point) or null"});
  w = "uniform";
  check_message(error_for(j), {"model.json: /cells/1/trivariate/weights: found the string \"uniform\"; expected null or an array of positive weights"});
}

TEST_CASE("surfaces take two orders and two knot vectors", "[io][json][bad]") {
  json j = valid_model();
  j["surfaces"][0]["surface"]["orders"] = {2, 2, 2};
  check_message(error_for(j), {"model.json: /surfaces/0/surface/orders: 3 orders; expected 2 orders"});
  j = valid_model();
  j["surfaces"][0].erase("surface");
  check_message(error_for(j), {"model.json: /surfaces/0: missing \"surface\"; expected {\"name\", \"surface\"}"});
}

TEST_CASE("a model needs at least one cell or surface", "[io][json][bad]") {
  check_message(error_of([] { read_model_json("{\"trivox\": 1, \"cells\": []}", "none.json"); }),
                {"none.json: top level: no cells and no surfaces; expected at least one"});
}

// --------------------------------------------------------------------------------------------
// Robustness: no input crashes the reader

TEST_CASE("truncated or corrupted model files only ever give trivox::Error", "[io][json][bad]") {
  const std::string text = write_model_json(read(valid_model()));
  int accepted = 0;
  // Every prefix: only the full text (and the text without its final newline) are valid.
  for (std::size_t n = 0; n < text.size(); ++n) {
    try {
      read_model_json(std::string_view(text).substr(0, n), "cut.json");
      ++accepted;
    } catch (const trivox::Error&) {
    }
  }
  CHECK(accepted == 1);
  // Random byte substitutions, from a fixed seed.
  std::mt19937 rng(7);
  using namespace std::string_literals;
  const std::string alphabet = "{}[],:\"0123456789.eE+- \nnulltruefalse\x00\xff"s;
  for (int trial = 0; trial < 3000; ++trial) {
    std::string t = text;
    for (int e = 0; e < 3; ++e)
      t[rng() % t.size()] = alphabet[rng() % alphabet.size()];
    try {
      read_model_json(t, "fuzz.json");
    } catch (const trivox::Error& e) {
      CHECK_THAT(std::string(e.what()), Catch::StartsWith("fuzz.json: "));
    }
  }
}

// --------------------------------------------------------------------------------------------
// Large files: the cells' elements are parsed in parallel (json_io::parse_split)

namespace {
/// awkward_model plus big cells (about 8 MB of text each), so that the text passes the
/// threshold of the parallel parse.
VModel big_model() {
  VModel m = awkward_model();
  std::mt19937_64 rng(77);
  for (int c = 0; c < 2; ++c) {
    const KnotVector k = KnotVector::uniform(4, 37);  // 40 functions per direction
    std::vector<double> pts;
    for (int i = 0; i < 40 * 40 * 40 * 6; ++i) pts.push_back(random_finite(rng));
    m.cells.push_back({"big" + std::to_string(c), Trivariate({k, k, k}, 6, pts)});
  }
  return m;
}
/// Line and column of byte `at` (1-based), counted independently of the reader.
std::string line_column(const std::string& text, std::size_t at) {
  std::size_t line = 1, col = 1;
  for (std::size_t i = 0; i < at; ++i) {
    if (text[i] == '\n') ++line, col = 1;
    else ++col;
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(col);
}
}  // namespace

TEST_CASE("a large model reads the same as through one serial parse, errors included", "[io][json]") {
  const VModel m = big_model();
  const std::string text = write_model_json(m);
  REQUIRE(text.size() > (std::size_t{8} << 20));
  const VModel back = read_model_json(text, "big.json");
  // (In parentheses: Catch would print a failing comparison's million-element operands.)
  CHECK((back == m));
  CHECK((bits(back) == bits(m)));
  // A top-level key spelled with an escape takes the one-parse path (the split skips such
  // documents): the same model.
  std::string escaped = text;
  const auto units = escaped.find("\"units\"");
  REQUIRE(units != std::string::npos);
  escaped.replace(units, 7, "\"\\u0075nits\"");
  CHECK((bits(read_model_json(escaped, "big.json")) == bits(m)));

  // A syntax error deep in the last big cell: the position of the whole file.
  std::string broken = text;
  const auto at = broken.rfind("big1");
  const auto digit = broken.find_first_of("0123456789", broken.find("\"points\"", at));
  REQUIRE(digit != std::string::npos);
  broken.insert(digit, "x");
  check_message(error_of([&] { read_model_json(broken, "big.json"); }),
                {"big.json: " + line_column(broken, digit) + ": malformed JSON"});

  // Errors in two cells: the one a serial reading meets first. A bad order in cell 2 ("big0")
  // comes before a repeated name in cell 3.
  json doc = json::parse(text);
  doc["cells"][2]["trivariate"]["orders"][0] = 0;
  doc["cells"][3]["name"] = "big0";
  const std::string two = doc.dump(1);
  REQUIRE(two.size() > (std::size_t{8} << 20));
  check_message(error_of([&] { read_model_json(two, "big.json"); }), {"big.json: /cells/2/trivariate/orders/0"});
  doc["cells"][2]["trivariate"]["orders"][0] = 4;
  check_message(error_of([&] { read_model_json(doc.dump(1), "big.json"); }),
                {"big.json: /cells/3/name", "is also the name of /cells/2"});
}
