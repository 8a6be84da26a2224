// The scene reader and builder (io/scene.hpp). Truths: the documented scene format
// (docs/model-format.md, "Scenes"): what each key means, which cells a primitive expands to, and
// that every malformed scene is refused with the file, the JSON pointer and what was expected.
#include <catch2/catch.hpp>

#include <string>

#include "../io/io_test_util.hpp"
#include "trivox/scene/scene.hpp"

using namespace trivox;
using trivox::io::test::check_message;
using trivox::io::test::error_of;

namespace {

/// A scene with one property "d" and the given cells and operations.
std::string scene_text(const std::string& cells, const std::string& ops = "") {
  return R"({"trivox": 1, "units": "cm", "properties": ["d"], "cells": [)" + cells + R"(], "operations": [)" + ops + "]}";
}

const std::string ball = R"({"name": "ball", "primitive": {"type": "sphere", "center": [1, 2, 3], "radius": 2},
                              "field": {"constant": 0.5}})";
const std::string block = R"({"name": "block", "trivariate": {"orders": [2, 2, 2],
  "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
  "points": [[0,0,0,1], [1,0,0,1], [0,1,0,1], [1,1,0,1], [0,0,1,1], [1,0,1,1], [0,1,1,1], [1,1,1,1]]}})";

std::string read_error(const std::string& text) {
  return error_of([&] { scene::read_scene_json(text, "s.json"); });
}
std::string build_error(const std::string& text) {
  return error_of([&] { scene::build_scene(scene::read_scene_json(text, "s.json")); });
}

}  // namespace

TEST_CASE("scene: primitives expand to named cells with their fields", "[scene]") {
  const auto s = scene::read_scene_json(scene_text(ball + "," + block), "s.json");
  CHECK(s.units == "cm");
  CHECK(s.properties == std::vector<std::string>{"d"});
  REQUIRE(s.cells.size() == 2);
  CHECK(s.cells[0].pointer == "/cells/0");
  const auto built = scene::build_scene(s);
  REQUIRE(built.model.cells.size() == 8);
  CHECK(built.model.cells[0].name == "ball.core");
  CHECK(built.model.cells[6].name == "ball.z1");
  CHECK(built.model.cells[7].name == "block");
  REQUIRE(built.primitives.size() == 1);
  CHECK(built.primitives[0].type == "sphere");
  CHECK(built.primitives[0].cell_count == 7);
  CHECK(built.primitives[0].exact_volume == Approx(4.0 / 3.0 * 3.14159265358979323846 * 8));
  CHECK(built.primitives[0].field.exact);
  for (const auto& c : built.model.cells) {
    CHECK(c.volume.dim() == 4);
    CHECK(std::abs(c.volume.eval({0.3, 0.6, 0.9})[3] - (c.name == "block" ? 1.0 : 0.5)) < 1e-15);
  }
  // A ball's centre cell is centred on the ball.
  const auto centre = built.model.cells[0].volume.eval({0.5, 0.5, 0.5});
  CHECK(centre[0] == Approx(1.0));
  CHECK(centre[1] == Approx(2.0));
  CHECK(centre[2] == Approx(3.0));
}

TEST_CASE("scene: field forms and the primitive tolerance", "[scene]") {
  const std::string two = R"({"trivox": 1, "properties": ["a", "b"], "cells": [
    {"name": "c", "primitive": {"type": "cylinder", "base": [0, 0, 0], "axis": [0, 0, 1], "radius": 1, "height": 2,
                                "tolerance": 1e-3},
     "field": {"linear": {"from": [0, 0, -1], "to": [0, 0, 3], "values": [[0, 1], [1, 0]]}}}]})";
  const auto built = scene::build_scene(scene::read_scene_json(two, "s.json"));
  REQUIRE(built.model.cells.size() == 5);
  CHECK(built.primitives[0].field.exact);
  const auto x = built.model.cells[2].volume.eval({0.2, 0.7, 0.5});
  CHECK(std::abs(x[3] - (x[2] + 1) / 4) < 1e-12);
  CHECK(std::abs(x[4] - (1 - (x[2] + 1) / 4)) < 1e-12);
  // No properties: no field needed.
  const auto plain = scene::build_scene(scene::read_scene_json(
      R"({"trivox": 1, "cells": [{"name": "t", "primitive": {"type": "torus", "center": [0, 0, 0], "axis": [0, 0, 1],
          "major": 3, "minor": 1}}]})", "s.json"));
  CHECK(plain.model.cells.size() == 5);
  CHECK(plain.model.cells[0].volume.dim() == 3);
  CHECK_FALSE(plain.primitives[0].has_field);
}

TEST_CASE("scene: malformed scenes name the file, the place and what was expected", "[scene]") {
  check_message(read_error("{\"trivox\": 1, \"cells\": [}"), {"s.json: line 1", "malformed JSON"});
  check_message(read_error(R"({"trivox": 2, "cells": []})"), {"s.json: /trivox: format version 2; expected 1"});
  check_message(read_error(scene_text("")), {"s.json: top level: no cells and no surfaces; expected"});
  check_message(read_error(scene_text(R"({"name": "a"})")),
                {"s.json: /cells/0: neither \"trivariate\" nor \"primitive\"; expected"});
  check_message(read_error(scene_text(R"({"name": "a", "primitive": 3})")), {"s.json: /cells/0/primitive: found the number 3; expected a primitive"});
  check_message(read_error(scene_text(R"({"name": "a", "primitive": {"radius": 1}, "field": {"constant": 1}})")),
                {"s.json: /cells/0/primitive: missing \"type\"; expected a primitive"});
  check_message(read_error(scene_text(R"({"name": "a", "primitive": {"type": "egg"}, "field": {"constant": 1}})")),
                {"s.json: /cells/0/primitive/type: unknown primitive type \"egg\"; expected \"box\", \"cylinder\""});
  check_message(read_error(scene_text(R"({"name": "a", "primitive": {"type": "sphere", "center": [0, 0]}, "field": {"constant": 1}})")),
                {"s.json: /cells/0/primitive/center: 2 numbers; expected a point or vector [x, y, z]"});
  check_message(read_error(scene_text(R"({"name": "a", "primitive": {"type": "sphere", "center": [0, 0, 0]}, "field": {"constant": 1}})")),
                {"s.json: /cells/0/primitive: missing \"radius\"; expected sphere {\"center\", \"radius\"}"});
  check_message(read_error(scene_text(R"({"name": "a", "primitive": {"type": "sphere", "center": [0, "x", 0], "radius": 1}, "field": {"constant": 1}})")),
                {"s.json: /cells/0/primitive/center/1: found the string \"x\"; expected a number"});
  check_message(read_error(scene_text(R"({"name": "a", "primitive": {"type": "cylinder", "base": [0, 0, 0], "axis": [0, 0, 0], "radius": 1, "height": 1}, "field": {"constant": 1}})")),
                {"s.json: /cells/0/primitive: cylinder axis (0, 0, 0) has zero length; expected a non-zero direction"});
  check_message(read_error(scene_text(R"({"name": "a", "primitive": {"type": "cone", "base": [0, 0, 0], "axis": [0, 0, 1], "radius": 1, "top_radius": 0, "height": 1}, "field": {"constant": 1}})")),
                {"s.json: /cells/0/primitive: cone top_radius 0", "expected a positive top_radius"});
  check_message(read_error(scene_text(R"({"name": "a", "primitive": {"type": "box", "min": [0, 0, 0], "max": [1, 1, 1], "tolerance": 0.5}, "field": {"constant": 1}})")),
                {"s.json: /cells/0/primitive/tolerance: tolerance 0.5; expected a relative tolerance in [1e-8, 0.01]"});
  check_message(read_error(scene_text(R"({"name": "a", "primitive": {"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]}})")),
                {"s.json: /cells/0: missing \"field\"; expected a property field"});
  check_message(read_error(scene_text(R"({"name": "a", "primitive": {"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]}, "field": {}})")),
                {"s.json: /cells/0/field: no field kind; expected exactly one of"});
  check_message(read_error(scene_text(R"({"name": "a", "primitive": {"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]}, "field": {"constant": [1, 2]}})")),
                {"s.json: /cells/0/field/constant: 2 values; expected a number or an array of 1 number"});
  check_message(read_error(scene_text(R"({"name": "a", "primitive": {"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]}, "field": {"linear": {"from": [0, 0, 0], "to": [1, 0, 0], "values": [0]}}})")),
                {"s.json: /cells/0/field/linear/values: 1 entry; expected two value lists [v0, v1]"});
  check_message(read_error(scene_text(R"({"name": "a", "primitive": {"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]}, "field": {"linear": {"from": [0, 0, 0], "to": [0, 0, 0], "values": [0, 1]}}})")),
                {"s.json: /cells/0/field: linear field from = to; expected two distinct points"});
  check_message(read_error(scene_text(R"({"name": "a", "primitive": {"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]}, "field": {"radial": {"center": [0, 0, 0], "radius": -2, "values": [0, 1]}}})")),
                {"s.json: /cells/0/field: radial field radius -2; expected a positive finite number"});
  check_message(read_error(scene_text(block.substr(0, block.size() - 1) + R"(, "field": {"constant": 1}})")),
                {"s.json: /cells/0/field: a field on a trivariate cell; expected fields on primitive cells only"});
  check_message(read_error(scene_text(ball + "," + ball)), {"s.json: /cells/1/name: \"ball\" is also the name of /cells/0; expected"});
  check_message(read_error(scene_text(ball, R"({"op": 7})")), {"s.json: /operations/0/op: found the number 7; expected an operation name"});
  check_message(read_error(scene_text(ball, R"({"a": 1})")), {"s.json: /operations/0: missing \"op\"; expected an operation"});
  check_message(read_error(scene_text(ball, R"({"op": "blend"})")),
                {"s.json: /operations/0/op: unknown operation \"blend\"; expected one of \"union\", \"intersection\", "
                 "\"subtraction\", \"fillet\", \"ruled\", \"extrude\", \"revolve\", \"boolean_sum\", \"half_boolean_sum\", \"sweep\""});
}

TEST_CASE("scene: the constructors need a name; expanded names must stay unique", "[scene]") {
  // union, intersection, subtraction (tests/cli/booleans.sh), fillet (tests/cli/fillet.sh) and the
  // constructors (tests/cli/teapot.sh, tests/cli/build.sh) are built.
  for (const char* op : {"ruled", "extrude", "revolve", "boolean_sum", "half_boolean_sum", "sweep"}) {
    INFO(op);
    check_message(build_error(scene_text(ball, std::string(R"({"op": ")") + op + "\"}")),
                  {"s.json: /operations/0: missing \"name\"", "expected"});
  }
  const std::string clash = R"({"name": "ball.core", "trivariate": {"orders": [2, 2, 2],
    "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
    "points": [[0,0,0,1], [1,0,0,1], [0,1,0,1], [1,1,0,1], [0,0,1,1], [1,0,1,1], [0,1,1,1], [1,1,1,1]]}})";
  check_message(build_error(scene_text(clash + "," + ball)),
                {"s.json: /cells/1/name: cell \"ball.core\" (from \"ball\") is also a cell of /cells/0; expected unique cell names"});
}

TEST_CASE("scene: fillet parameters are checked where they are written", "[scene][fillet]") {
  const std::string two = ball + R"(, {"name": "box", "primitive": {"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]},
    "field": {"constant": 1}})";
  const auto op = [&](const std::string& fields) { return scene_text(two, R"({"op": "fillet", )" + fields + "}"); };
  const std::string between = R"("between": ["ball.x1", "box"], )";
  check_message(build_error(op(R"("distance": 1)")), {"s.json: /operations/0: missing \"between\""});
  check_message(build_error(op(R"("between": ["box"], "distance": 1)")),
                {"s.json: /operations/0/between: found an array of 1", "expected two cells"});
  check_message(build_error(op(R"("between": ["box", "box"], "distance": 1)")),
                {"/operations/0/between/1: \"box\" twice"});
  check_message(build_error(op(R"("between": [{"cell": "box", "face": "w2"}, "ball.x1"], "distance": 1)")),
                {"/operations/0/between/0/face: unknown face \"w2\"; expected u0, u1, v0, v1, w0 or w1"});
  check_message(build_error(op(between + R"("distance": [1, -2])")),
                {"/operations/0/distance: distance -2.0; expected positive distances"});
  check_message(build_error(op(between + R"("distance": 1, "tau": 0)")), {"/operations/0/tau: tau 0.0; expected a value in (0, 10]"});
  check_message(build_error(op(between + R"("distance": 1, "dip": 2)")), {"/operations/0/dip: dip 2.0; expected a value in [0, 1]"});
  check_message(build_error(op(between + R"("distance": 1, "section": "round")")),
                {"/operations/0/section: unknown section \"round\"; expected \"hermite\" or \"flend\""});
  check_message(build_error(op(between + R"("distance": 1, "method": "exact")")),
                {"/operations/0/method: unknown method \"exact\"; expected \"auto\", \"compose\", \"matched\" or \"fit\""});
  check_message(build_error(op(between + R"("distance": 1, "blend": "idw")")),
                {"/operations/0/blend: unknown blend \"idw\"; expected \"parametric\" or \"shepard\""});
  check_message(build_error(op(between + R"("distance": 1, "blend": "shepard", "power": 1.5)")),
                {"/operations/0/power: found", "expected a power q, an integer in 1..16"});
  check_message(build_error(op(between + R"("distance": 1, "power": 2)")),
                {"/operations/0/power: a power without \"blend\": \"shepard\""});
  check_message(build_error(op(between + R"("distance": 1, "flip": "yes")")),
                {"/operations/0/flip: found", "expected true, false or [bool, bool]"});
  check_message(build_error(op(R"("between": ["ball.x9", "box"], "distance": 1)")),
                {"/operations/0/between/0: no cell named \"ball.x9\""});
  check_message(build_error(op(R"("between": ["ball", "box"], "distance": 1)")),
                {"/operations/0/between/0: \"ball\" has 7 cells; expected one cell"});
}

TEST_CASE("scene: a ruled cell between two surfaces, properties riding along or from a field", "[scene]") {
  // Two unit squares at z = 0 and z = 2 carrying d = 0 and d = 1: the ruled cell is the box
  // [0,1]^2 x [0,2] and d = z / 2 exactly (affine in w).
  const auto square = [](double z, double d) {
    const std::string zs = std::to_string(z), ds = std::to_string(d);
    return R"({"orders": [2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1]], "points": [[0,0,)" + zs + "," + ds +
           "], [1,0," + zs + "," + ds + "], [0,1," + zs + "," + ds + "], [1,1," + zs + "," + ds + "]]}";
  };
  const std::string text = R"({"trivox": 1, "properties": ["d"], "surfaces": [{"name": "lo", "surface": )" +
                           square(0, 0) + R"(}, {"name": "hi", "surface": )" + square(2, 1) +
                           R"(}], "operations": [{"op": "ruled", "name": "box", "surfaces": ["lo", "hi"]}]})";
  const auto built = scene::build_scene(scene::read_scene_json(text, "s.json"));
  REQUIRE(built.model.cells.size() == 1);
  CHECK(built.model.cells[0].name == "box");
  const auto p = built.model.cells[0].volume.eval({0.3, 0.7, 0.25});
  CHECK(p[2] == Approx(0.5).margin(1e-15));
  CHECK(p[3] == Approx(0.25).margin(1e-15));
  REQUIRE(built.constructs.size() == 1);
  CHECK(built.constructs[0].cells == std::vector<std::string>{"box"});
  // A field replaces the surfaces' properties.
  std::string with_field = text;
  with_field.replace(with_field.find(R"("surfaces": ["lo", "hi"]})"), 25,
                     R"("surfaces": ["lo", "hi"], "field": {"constant": 0.75}})");
  const auto coloured = scene::build_scene(scene::read_scene_json(with_field, "s.json"));
  CHECK(coloured.model.cells[0].volume.eval({0.5, 0.5, 0.5})[3] == Approx(0.75).margin(1e-15));
  // Errors name the pointer.
  std::string missing = text;
  missing.replace(missing.find(R"(["lo", "hi"])"), 12, R"(["lo", "no"])");
  check_message(build_error(missing), {"s.json: /operations/0/surfaces/1: no surface named \"no\"", "expected"});
  std::string three = text;
  three.replace(three.find(R"(["lo", "hi"])"), 12, R"(["lo", "hi", "lo"])");
  check_message(read_error(three), {"s.json: /operations/0/surfaces: 3 surfaces; expected 2 surfaces", "expected"});
  std::string off = text;
  off.replace(off.find(R"("operations")"), 0, R"("extra": 0, )");
  off.replace(off.find(R"(}], "extra")"), 2, R"(}, {"name": "up", "offset": {"surface": "lo", "distance": 0}}])");
  check_message(read_error(off), {"s.json: /surfaces/2/offset/distance: distance 0", "expected"});
}
