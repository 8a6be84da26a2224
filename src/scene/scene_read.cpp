// Reading a scene file (scene.hpp): the JSON checked and turned into a Scene, every error
// naming the file and the JSON pointer of the offending value.
#include "trivox/scene/scene.hpp"

#include <algorithm>
#include <map>

#include "../io/json_io.hpp"
#include "../io/model_scan.hpp"
#include "scene_construct.hpp"

#include "trivox/error.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/limits.hpp"
#include "trivox/spline/extract.hpp"

namespace trivox::scene {

namespace {

using namespace io::json_io;
using construct::Vec3;

std::string known_operations() {
  std::string s;
  for (const char* op : scene_operations) s += (s.empty() ? "" : ", ") + quote(op);
  return s;
}

// ------------------------------------------------------------------------------------------
// Primitive parameters

Vec3 read_point(const Source& src, const json& obj, const std::string& ptr, const char* key, const std::string& what) {
  const std::string p = child(ptr, key);
  const std::string expected = "a point or vector [x, y, z]";
  const json& j = expect_array(src, require(src, obj, ptr, key, what), p, expected);
  if (j.size() != 3) src.fail(p, plural(static_cast<std::int64_t>(j.size()), "number") + "; expected " + expected);
  return {read_number_at(src, j[0], p, 0), read_number_at(src, j[1], p, 1), read_number_at(src, j[2], p, 2)};
}

double read_scalar(const Source& src, const json& obj, const std::string& ptr, const char* key, const std::string& what) {
  return read_number(src, require(src, obj, ptr, key, what), child(ptr, key));
}

constexpr const char* primitive_types = "\"box\", \"cylinder\", \"cone\", \"torus\" or \"sphere\"";

construct::Primitive read_primitive_params(const Source& src, const json& j, const std::string& ptr) {
  const std::string what = "a primitive {\"type\": " + std::string(primitive_types) + ", ...parameters}";
  expect_object(src, j, ptr, what);
  const std::string type = read_string(src, require(src, j, ptr, "type", what), child(ptr, "type"),
                                       std::string("a primitive type: ") + primitive_types);
  auto pt = [&](const char* key, const char* params) { return read_point(src, j, ptr, key, type + " " + params); };
  auto num = [&](const char* key, const char* params) { return read_scalar(src, j, ptr, key, type + " " + params); };
  if (type == "box") {
    const char* p = "{\"min\": [x, y, z], \"max\": [x, y, z]}";
    return construct::Box{pt("min", p), pt("max", p)};
  }
  if (type == "cylinder") {
    const char* p = "{\"base\", \"axis\", \"radius\", \"height\"}";
    return construct::Cylinder{pt("base", p), pt("axis", p), num("radius", p), num("height", p)};
  }
  if (type == "cone") {
    const char* p = "{\"base\", \"axis\", \"radius\", \"top_radius\", \"height\"}";
    return construct::Cone{pt("base", p), pt("axis", p), num("radius", p), num("top_radius", p), num("height", p)};
  }
  if (type == "torus") {
    const char* p = "{\"center\", \"axis\", \"major\", \"minor\"}";
    return construct::Torus{pt("center", p), pt("axis", p), num("major", p), num("minor", p)};
  }
  if (type == "sphere") {
    const char* p = "{\"center\", \"radius\"}";
    return construct::Sphere{pt("center", p), num("radius", p)};
  }
  src.fail(child(ptr, "type"), "unknown primitive type " + quote(type) + "; expected " + primitive_types);
}

// ------------------------------------------------------------------------------------------
// Fields

/// One value per property: an array of m numbers, or a plain number when m = 1.
std::vector<double> read_values(const Source& src, const json& j, const std::string& ptr, std::size_t m) {
  const std::string expected =
      m == 1 ? "a number or an array of 1 number (one value per property)"
             : "an array of " + std::to_string(m) + " numbers (one value per property)";
  if (j.is_number() && m == 1) return {read_number(src, j, ptr)};
  if (!j.is_array()) fail_type(src, ptr, j, expected);
  if (j.size() != m) src.fail(ptr, plural(static_cast<std::int64_t>(j.size()), "value") + "; expected " + expected);
  return read_numbers(src, j, ptr, expected);
}

/// The two value lists [v0, v1] of a linear or radial field.
std::array<std::vector<double>, 2> read_value_pair(const Source& src, const json& obj, const std::string& ptr,
                                                   const std::string& what, std::size_t m) {
  const std::string p = child(ptr, "values");
  const std::string expected = "two value lists [v0, v1]";
  const json& j = expect_array(src, require(src, obj, ptr, "values", what), p, expected);
  if (j.size() != 2) src.fail(p, plural(static_cast<std::int64_t>(j.size()), "entry") + "; expected " + expected);
  return {read_values(src, j[0], child(p, std::size_t{0}), m), read_values(src, j[1], child(p, std::size_t{1}), m)};
}

constexpr const char* field_kinds = "{\"constant\": values}, {\"linear\": {\"from\", \"to\", \"values\"}} or "
                                    "{\"radial\": {\"center\", \"radius\", \"values\"}}";

construct::Field read_field(const Source& src, const json& j, const std::string& ptr, std::size_t m) {
  const std::string what = std::string("a property field: ") + field_kinds;
  expect_object(src, j, ptr, what);
  int kinds = 0;
  for (const char* k : {"constant", "linear", "radial"}) kinds += j.contains(k) ? 1 : 0;
  if (kinds != 1)
    src.fail(ptr, (kinds == 0 ? std::string("no field kind") : std::to_string(kinds) + " field kinds") +
                      "; expected exactly one of " + field_kinds);
  if (const json* c = find(j, "constant")) return construct::ConstantField{read_values(src, *c, child(ptr, "constant"), m)};
  if (const json* l = find(j, "linear")) {
    const std::string lp = child(ptr, "linear");
    const std::string lw = "a linear field {\"from\": [x, y, z], \"to\": [x, y, z], \"values\": [v0, v1]}";
    expect_object(src, *l, lp, lw);
    auto [v0, v1] = read_value_pair(src, *l, lp, lw, m);
    return construct::LinearField{read_point(src, *l, lp, "from", lw), read_point(src, *l, lp, "to", lw), std::move(v0),
                                  std::move(v1)};
  }
  const json& r = *find(j, "radial");
  const std::string rp = child(ptr, "radial");
  const std::string rw = "a radial field {\"center\": [x, y, z], \"radius\": r, \"values\": [v_centre, v_radius]}";
  expect_object(src, r, rp, rw);
  auto [vc, vr] = read_value_pair(src, r, rp, rw, m);
  return construct::RadialField{read_point(src, r, rp, "center", rw), read_scalar(src, r, rp, "radius", rw), std::move(vc),
                                std::move(vr)};
}

ScenePrimitive read_primitive_cell(const Source& src, const json& cell, const std::string& ptr, std::size_t m) {
  const std::string pp = child(ptr, "primitive");
  ScenePrimitive out{read_primitive_params(src, cell["primitive"], pp), {}, std::nullopt};
  try {
    construct::check_primitive(out.primitive);
  } catch (const Error& e) {
    throw e.within(src.at(pp));
  }
  if (const json* t = find(cell["primitive"], "tolerance")) {
    const std::string tp = child(pp, "tolerance");
    const double tol = read_number(src, *t, tp);
    if (!(tol >= 1e-8 && tol <= 0.01))
      src.fail(tp, "tolerance " + format_double(tol) + "; expected a relative tolerance in [1e-8, 0.01]");
    out.options.relative_tolerance = tol;
  }
  if (const json* f = find(cell, "field")) {
    const std::string fp = child(ptr, "field");
    out.field = read_field(src, *f, fp, m);
    try {
      construct::check_field(*out.field, static_cast<int>(m));
    } catch (const Error& e) {
      throw e.within(src.at(fp));
    }
  } else if (m > 0) {
    src.fail(ptr, "missing \"field\"; expected a property field (" + std::string(field_kinds) + ") giving the " +
                      plural(static_cast<std::int64_t>(m), "property") + " of /properties");
  }
  return out;
}

// ------------------------------------------------------------------------------------------
// Cells, surfaces, operations

std::vector<SceneCell> read_cells(const Source& src, const json& root, const PointShape& shape, std::size_t m,
                                  NameTable& names) {
  const json* j = find(root, "cells");
  if (j == nullptr) return {};
  const std::string what = "{\"name\", \"trivariate\"} or {\"name\", \"primitive\", \"field\"}";
  expect_array(src, *j, "/cells", "an array of cell objects " + what);
  std::vector<SceneCell> out;
  for (std::size_t i = 0; i < j->size(); ++i) {
    const std::string ip = child("/cells", i);
    const json& item = expect_object(src, (*j)[i], ip, "a cell object " + what);
    std::string name = read_name(src, item, ip, names);
    const bool tri = item.contains("trivariate"), prim = item.contains("primitive");
    if (tri == prim)
      src.fail(ip, std::string(tri ? "both \"trivariate\" and \"primitive\"" : "neither \"trivariate\" nor \"primitive\"") +
                       "; expected a cell with exactly one of them");
    if (tri) {
      if (item.contains("field"))
        src.fail(child(ip, "field"), "a field on a trivariate cell; expected fields on primitive cells only (a "
                                     "trivariate carries its properties in its control points)");
      out.push_back({std::move(name), ip, read_spline<3>(src, item["trivariate"], child(ip, "trivariate"), shape)});
    } else {
      out.push_back({std::move(name), ip, read_primitive_cell(src, item, ip, m)});
    }
  }
  return out;
}

std::vector<vmodel::NamedSurface> read_surfaces(const Source& src, const json& root, const PointShape& shape,
                                                NameTable& names, std::vector<SceneSurfaceRecipe>& derived) {
  const json* j = find(root, "surfaces");
  if (j == nullptr) return {};
  const std::string what = "{\"name\", \"surface\"}";
  expect_array(src, *j, "/surfaces", "an array of " + what + " objects");
  std::vector<vmodel::NamedSurface> out;
  for (std::size_t i = 0; i < j->size(); ++i) {
    const std::string ip = child("/surfaces", i);
    const json& item = expect_object(src, (*j)[i], ip, "an object " + what);
    std::string name = read_name(src, item, ip, names);
    if (detail::is_derived_surface(item)) {  // "gismo" patches or an "offset" (scene_construct.hpp)
      derived.push_back(detail::read_derived_surface(src, item, ip, std::move(name)));
      continue;
    }
    out.push_back({std::move(name), read_spline<2>(src, require(src, item, ip, "surface", what), child(ip, "surface"), shape)});
  }
  return out;
}

/// {"op": "fillet", ...}: see scene.hpp.
void read_fillet(const Source& src, const json& item, const std::string& ip, SceneOperation& o) {
  const std::string what =
      "a fillet {\"op\": \"fillet\", \"between\": [A, B], \"distance\", \"tau\", \"section\", \"dip\", "
      "\"method\", \"blend\", \"power\", \"flip\", \"construction\", \"bridge\", \"corners\", \"name\"}";
  const std::string bp = child(ip, "between");
  const json& between = require(src, item, ip, "between", what);
  const std::string bwhat = "two cells: names or {\"cell\": NAME, \"face\": \"u0\"..\"w1\"}, or lists of "
                            "{\"cell\", \"face\"} (a fillet over several faces)";
  if (!between.is_array() || between.size() != 2) fail_type(src, bp, between, bwhat);
  const auto read_face = [&](const json& e, const std::string& ep, SceneOperation::SideFace& out) {
    if (!e.is_object()) fail_type(src, ep, e, "{\"cell\": NAME, \"face\": \"u0\"..\"w1\"}");
    out.cell = read_string(src, require(src, e, ep, "cell", bwhat), child(ep, "cell"), "a cell name");
    if (out.cell.empty()) src.fail(child(ep, "cell"), "empty cell name; expected a cell name");
    const std::string face =
        read_string(src, require(src, e, ep, "face", bwhat), child(ep, "face"), "a face name u0 u1 v0 v1 w0 w1");
    try {
      out.face = spline::face_from_name(face);
    } catch (const Error&) {
      src.fail(child(ep, "face"), "unknown face " + quote(face) + "; expected u0, u1, v0, v1, w0 or w1");
    }
    out.pointer = ep;
  };
  o.across = between[0].is_array() || between[1].is_array();
  if (o.across) {
    // Masalha et al. 2021, Sec. 6: every listed face of one side against every
    // listed face of the other.
    for (std::size_t i = 0; i < 2; ++i) {
      const std::string ep = child(bp, i);
      const json& e = between[i];
      if (e.is_object()) {
        o.sides[i].emplace_back();
        read_face(e, ep, o.sides[i].back());
      } else if (e.is_array() && !e.empty()) {
        for (std::size_t k = 0; k < e.size(); ++k) {
          o.sides[i].emplace_back();
          read_face(e[k], child(ep, k), o.sides[i].back());
          for (std::size_t l = 0; l < k; ++l)
            if (o.sides[i][l].cell == o.sides[i][k].cell && o.sides[i][l].face == o.sides[i][k].face)
              src.fail(child(ep, k), quote(o.sides[i][k].cell) + " face " +
                                         std::string(spline::face_name(o.sides[i][k].face)) + " twice; expected each face once");
        }
      } else {
        fail_type(src, ep, e, "a non-empty list of {\"cell\", \"face\"} or one {\"cell\", \"face\"} (a fillet over several faces names its faces)");
      }
      o.between[i] = o.sides[i].front().cell;
    }
    for (const auto& a : o.sides[0])
      for (const auto& b : o.sides[1])
        if (a.cell == b.cell)
          src.fail(b.pointer, quote(b.cell) + " on both sides; expected faces of two different bodies");
  }
  for (std::size_t i = 0; i < 2 && !o.across; ++i) {
    const std::string ep = child(bp, i);
    const json& e = between[i];
    if (e.is_string()) {
      o.between[i] = e.get<std::string>();
    } else if (e.is_object()) {
      o.between[i] = read_string(src, require(src, e, ep, "cell", bwhat), child(ep, "cell"), "a cell name");
      const std::string face =
          read_string(src, require(src, e, ep, "face", bwhat), child(ep, "face"), "a face name u0 u1 v0 v1 w0 w1");
      try {
        o.faces[i] = spline::face_from_name(face);
      } catch (const Error&) {
        src.fail(child(ep, "face"), "unknown face " + quote(face) + "; expected u0, u1, v0, v1, w0 or w1");
      }
    } else {
      fail_type(src, ep, e, bwhat);
    }
    if (o.between[i].empty()) src.fail(ep, "empty cell name; expected " + bwhat);
  }
  if (!o.across && o.between[0] == o.between[1])
    src.fail(child(bp, 1), quote(o.between[1]) + " twice; expected two different cells");
  fillet::FilletOptions& f = o.fillet;
  if (const json* c = find(item, "corners")) {
    const std::string cp = child(ip, "corners");
    const std::string v = read_string(src, *c, cp, "\"bridge\" or \"open\"");
    if (v != "bridge" && v != "open") src.fail(cp, "unknown corners " + quote(v) + "; expected \"bridge\" or \"open\"");
    if (!o.across)
      src.fail(cp, "\"corners\" with one face per side; expected lists of faces in \"between\" (a fillet over "
                   "several faces, Masalha et al. 2021, Sec. 6)");
    o.corners.bridge = v == "bridge";
  }
  if (o.across)
    for (const char* key : {"bridge", "construction", "blend", "power"})
      if (find(item, key))
        src.fail(child(ip, key), std::string("\"") + key + "\" with a fillet over several faces; expected the ruled "
                                 "construction and the parametric blend (Masalha et al. 2021, Sec. 6 joins ruled fillets)");
  if (const json* b = find(item, "bridge")) {
    if (!b->is_boolean()) fail_type(src, child(ip, "bridge"), *b, "true or false");
    o.bridge = b->get<bool>();
  }
  if (o.bridge) {
    // Flends Sec. III between disjoint faces: the faces, dip and name; no distances or tangents.
    if (!o.faces[0] || !o.faces[1])
      src.fail(bp, "a bridge names both faces; expected [{\"cell\", \"face\"}, {\"cell\", \"face\"}]");
    for (const char* key : {"distance", "tau", "method", "flip", "blend", "power", "construction"})
      if (find(item, key)) src.fail(child(ip, key), std::string("\"") + key + "\" with \"bridge\": true; expected "
                                                         "only \"between\", \"section\": \"flend\", \"dip\" and \"name\"");
    f.blend.section = fillet::Section::flend;
  }
  if (!o.bridge) {
    const json& d = require(src, item, ip, "distance", what);
    const std::string dp = child(ip, "distance");
    if (d.is_array()) {
      if (d.size() != 2) fail_type(src, dp, d, "a distance or two [d1, d2]");
      f.distance = {read_number_at(src, d[0], dp, 0), read_number_at(src, d[1], dp, 1)};
    } else {
      f.distance[0] = f.distance[1] = read_number(src, d, dp);
    }
    for (double x : f.distance)
      if (!(x > 0.0)) src.fail(dp, "distance " + format_double(x) + "; expected positive distances (model units)");
  }
  if (const json* t = find(item, "tau")) {
    f.blend.tau = read_number(src, *t, child(ip, "tau"));
    if (!(f.blend.tau > 0.0 && f.blend.tau <= 10.0))
      src.fail(child(ip, "tau"), "tau " + format_double(f.blend.tau) + "; expected a value in (0, 10]");
  }
  if (const json* t = find(item, "section")) {
    const std::string sec = read_string(src, *t, child(ip, "section"), "\"hermite\" or \"flend\"");
    if (!fillet::section_from_name(sec.c_str(), f.blend.section))
      src.fail(child(ip, "section"), "unknown section " + quote(sec) + "; expected \"hermite\" or \"flend\"");
    if (o.across && o.corners.bridge && f.blend.section != fillet::Section::hermite)
      src.fail(child(ip, "section"), "the bridging fillets at corners (Masalha et al. 2021, Sec. 6.1) take the Hermite section; "
                                     "expected \"section\": \"hermite\", or \"corners\": \"open\"");
    if (o.bridge && f.blend.section != fillet::Section::flend)
      src.fail(child(ip, "section"), "a bridge is a flend (Eager & Dannenhoffer 2019, Sec. III); expected \"section\": \"flend\"");
  }
  if (const json* t = find(item, "dip")) {
    f.blend.dip = read_number(src, *t, child(ip, "dip"));
    if (!(f.blend.dip >= 0.0 && f.blend.dip <= 1.0))
      src.fail(child(ip, "dip"), "dip " + format_double(f.blend.dip) + "; expected a value in [0, 1]");
  }
  if (const json* t = find(item, "method")) {
    const std::string m = read_string(src, *t, child(ip, "method"), "\"auto\", \"compose\", \"matched\" or \"fit\"");
    if (!fillet::subregion_method_from_name(m.c_str(), f.method))
      src.fail(child(ip, "method"), "unknown method " + quote(m) + "; expected \"auto\", \"compose\", \"matched\" or \"fit\"");
  }
  if (const json* t = find(item, "blend")) {
    const std::string b = read_string(src, *t, child(ip, "blend"), "\"parametric\" or \"shepard\"");
    if (b != "parametric" && b != "shepard")
      src.fail(child(ip, "blend"), "unknown blend " + quote(b) + "; expected \"parametric\" or \"shepard\"");
    o.shepard = b == "shepard";
  }
  if (const json* t = find(item, "power")) {  // Shepard's q (fillet/shepard.hpp)
    o.shepard_power = read_int(src, *t, child(ip, "power"), 1, 16, "a power q, an integer in 1..16");
    if (!o.shepard) src.fail(child(ip, "power"), "a power without \"blend\": \"shepard\"; expected it only with the Shepard blend");
  }
  if (const json* t = find(item, "construction")) {  // Masalha et al. 2021, Alg. 2, Sec. 3.2 / Alg. 3 or Sec. 5 / Alg. 6
    const std::string cp = child(ip, "construction");
    const std::string c = read_string(src, *t, cp, "\"ruled\", \"vbs\" or \"vrep\"");
    if (!fillet::construction_from_name(c.c_str(), f.construction))
      src.fail(cp, "unknown construction " + quote(c) + "; expected \"ruled\", \"vbs\" or \"vrep\"");
    if (f.construction != fillet::Construction::ruled && o.shepard)
      src.fail(cp, quote(c) + " with \"blend\": \"shepard\"; expected \"ruled\" for the Shepard blend (its encoding "
                   "works on the ruled halves)");
  }
  if (const json* t = find(item, "flip")) {
    const std::string fp = child(ip, "flip");
    if (t->is_boolean()) {
      f.flip[0] = f.flip[1] = t->get<bool>();
    } else if (t->is_array() && t->size() == 2 && (*t)[0].is_boolean() && (*t)[1].is_boolean()) {
      f.flip = {(*t)[0].get<bool>(), (*t)[1].get<bool>()};
    } else {
      fail_type(src, fp, *t, "true, false or [bool, bool]");
    }
  }
  o.name = "fillet";
  if (const json* n = find(item, "name")) {
    o.name = read_string(src, *n, child(ip, "name"), "a non-empty result name");
    if (o.name.empty()) src.fail(child(ip, "name"), "empty name; expected a non-empty result name");
  }
}

std::vector<SceneOperation> read_operations(const Source& src, const json& root, std::size_t properties) {
  const json* j = find(root, "operations");
  if (j == nullptr) return {};
  const std::string what = "an operation {\"op\": " + known_operations() + ", ...}";
  expect_array(src, *j, "/operations", "an array of operations, each " + what);
  std::vector<SceneOperation> out;
  for (std::size_t i = 0; i < j->size(); ++i) {
    const std::string ip = child("/operations", i);
    const json& item = expect_object(src, (*j)[i], ip, what);
    const std::string op_ptr = child(ip, "op");
    const std::string op = read_string(src, require(src, item, ip, "op", what), op_ptr, "an operation name");
    bool known = false;
    for (const char* k : scene_operations) known = known || op == k;
    if (!known) src.fail(op_ptr, "unknown operation " + quote(op) + "; expected one of " + known_operations());
    SceneOperation o;
    o.op = op;
    o.pointer = ip;
    if (op == "union" || op == "intersection" || op == "subtraction") {
      const std::string bwhat = "a Boolean {\"op\", \"a\": NAME, \"b\": NAME, \"name\", \"blend\", \"power\"}";
      o.a = read_string(src, require(src, item, ip, "a", bwhat), child(ip, "a"), "the name of a cell or earlier result");
      o.b = read_string(src, require(src, item, ip, "b", bwhat), child(ip, "b"), "the name of a cell or earlier result");
      o.name = o.a;
      if (const json* n = find(item, "name")) {
        o.name = read_string(src, *n, child(ip, "name"), "a non-empty result name");
        if (o.name.empty()) src.fail(child(ip, "name"), "empty name; expected a non-empty result name");
      }
      if (const json* bl = find(item, "blend")) {
        const std::string expected = "a blend rule: \"sum_clip\", \"mean\", \"first\" or \"distance\"";
        const std::string rule = read_string(src, *bl, child(ip, "blend"), expected);
        if (!vmodel::blend_rule_from_name(rule, o.blend))
          src.fail(child(ip, "blend"), "unknown blend rule " + quote(rule) + "; expected " + expected);
      }
      if (const json* pw = find(item, "power")) {
        o.power = read_number(src, *pw, child(ip, "power"));
        if (!(o.power > 0 && o.power <= 64))
          src.fail(child(ip, "power"), "power " + format_double(o.power) + "; expected a power in (0, 64]");
      }
    }
    if (op == "fillet") read_fillet(src, item, ip, o);
    if (detail::is_constructor(op)) detail::read_constructor(src, item, ip, o, properties);
    out.push_back(std::move(o));
  }
  return out;
}

/// A model cell by name: a cell of any object, or an object of one cell.

}  // namespace

construct::Field detail::read_field(const Source& src, const json& j, const std::string& ptr, std::size_t properties) {
  return scene::read_field(src, j, ptr, properties);
}

Scene read_scene_json(std::string_view text, const std::string& source) {
  const Source src{source};
  // The trivariate cells and surfaces a scene holds obey the model limits (trivox/limits.hpp),
  // checked before the tree is built.
  io::scan_model_json(text, source, default_limits());
  const json root = parse(src, text);
  expect_object(src, root, "", "a trivox scene object {\"trivox\": 1, \"cells\": [...], ...}");
  check_version(src, root);
  Scene scene;
  scene.source = source;
  scene.units = read_units(src, root);
  scene.properties = read_properties(src, root);
  const PointShape shape = point_shape(scene.properties.size());
  NameTable names;
  scene.cells = read_cells(src, root, shape, scene.properties.size(), names);
  scene.surfaces = read_surfaces(src, root, shape, names, scene.derived_surfaces);
  scene.operations = read_operations(src, root, scene.properties.size());
  if (scene.cells.empty() && scene.surfaces.empty() && scene.derived_surfaces.empty())
    src.fail("", "no cells and no surfaces; expected at least one cell (\"cells\") or surface (\"surfaces\")");
  return scene;
}

Scene load_scene(const std::filesystem::path& path) {
  return read_scene_json(io::read_file(path, default_limits()), path.string());
}

}  // namespace trivox::scene
