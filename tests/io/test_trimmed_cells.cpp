// Trimmed cells (Booleans' within / without / blend) in the model file: exact round trip of a
// nested Boolean result, and located errors for malformed trimming.
#include <catch2/catch.hpp>

#include "io_test_util.hpp"
#include "trivox/io/model_json.hpp"
#include "trivox/vmodel/boolean.hpp"

using namespace trivox;
using trivox::io::test::check_message;
using trivox::io::test::error_of;

namespace {

vmodel::VModel box(const std::string& name, double x0, double x1, double value) {
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) pts.insert(pts.end(), {i ? x1 : x0, double(j), double(k), value});
  const spline::KnotVector b = spline::KnotVector::bezier(2);
  vmodel::VModel m;
  m.properties = {"r"};
  m.cells.push_back({name, spline::Trivariate({b, b, b}, 4, pts)});
  return m;
}

}  // namespace

TEST_CASE("trimmed cells round-trip through the model file", "[model_json][boolean]") {
  using vmodel::BooleanOp;
  const auto u = vmodel::boolean(box("a", 0, 2, 0.1), box("b", 1, 3, 0.2), BooleanOp::union_op,
                                 {.blend = vmodel::BlendRule::mean});
  const auto m = vmodel::boolean(box("c", -1, 4, 0.3), u, BooleanOp::subtraction);
  const std::string text = io::write_model_json(m);
  const auto back = io::read_model_json(text, "m.json");
  CHECK(back == m);
  REQUIRE(back.cells.size() == 1);
  REQUIRE(back.cells[0].without.size() == 1);
  CHECK(back.cells[0].without[0].size() == 3);
  CHECK(back.cells[0].without[0][0].blend == vmodel::BlendRule::mean);
  CHECK(back.cells[0].without[0][0].within.size() == 1);
  CHECK(io::write_model_json(back) == text);
  // The distance blend keeps its power and both inputs' boundary faces (6 each).
  const auto d = vmodel::boolean(box("a", 0, 2, 0.1), box("b", 1, 3, 0.2), BooleanOp::intersection,
                                 {.blend = vmodel::BlendRule::distance, .power = 2.5});
  const auto dback = io::read_model_json(io::write_model_json(d), "d.json");
  CHECK(dback == d);
  REQUIRE(dback.cells[0].boundaries.size() == 2);
  CHECK(dback.cells[0].boundaries[1].size() == 6);
  CHECK(dback.cells[0].blend_power == 2.5);
}

TEST_CASE("malformed trimming is reported with its JSON pointer", "[model_json][boolean]") {
  const auto m = vmodel::boolean(box("a", 0, 2, 0.1), box("b", 1, 3, 0.2), vmodel::BooleanOp::intersection);
  std::string text = io::write_model_json(m);
  const auto replaced = [&](const std::string& from, const std::string& to) {
    std::string t = text;
    const auto at = t.find(from);
    REQUIRE(at != std::string::npos);
    return t.replace(at, from.size(), to);
  };
  check_message(error_of([&] { io::read_model_json(replaced("\"sum_clip\"", "\"pizza\""), "m.json"); }),
                {"m.json", "/cells/0/blend", "unknown blend rule \"pizza\"", "expected"});
  check_message(error_of([&] { io::read_model_json(replaced("\"within\": [", "\"within\": [3, "), "m.json"); }),
                {"m.json", "/cells/0/within/0", "expected an object"});
  check_message(error_of([&] { io::read_model_json(replaced("\"within\": [", "\"without\": [{}], \"within\": ["), "m.json"); }),
                {"m.json", "/cells/0/without/0", "expected a solid"});
}
