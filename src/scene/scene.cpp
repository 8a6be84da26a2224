#include "trivox/scene/scene.hpp"

#include <algorithm>
#include <chrono>
#include <map>

#include "../io/json_io.hpp"
#include "scene_construct.hpp"

#include "trivox/error.hpp"
#include "trivox/fillet/shepard.hpp"
#include "trivox/geom/surface_intersection.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/slice/trim.hpp"
#include "trivox/vmodel/boolean.hpp"

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
    // Masalha et al. 2021, Sec. 6: every listed face of one side against every listed face of the other.
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
template <class Objects>
const vmodel::VCell& find_cell(const Source& src, const Objects& objects, const std::string& name, const std::string& ptr) {
  for (const auto& o : objects) {
    for (const auto& c : o.cells)
      if (c.name == name) return c;
    if (o.name == name && o.cells.size() == 1) return o.cells.front();
    if (o.name == name)
      src.fail(ptr, quote(name) + " has " + std::to_string(o.cells.size()) +
                        " cells; expected one cell: name it (" + quote(o.cells.front().name) + ", ...)");
  }
  src.fail(ptr, "no cell named " + quote(name) + "; expected the name of a model cell (a primitive's cells are "
                "<name>.<part>)");
}

/// Masalha et al. 2021, Sec. 6 / 6.1: the fillet over several faces (fillet/corners.hpp): its pieces' cells
/// <name>.<k>a, <name>.<k>b in chain order, the bridges' <name>.c<j>a, <name>.c<j>b.
template <class Objects>
std::vector<vmodel::VCell> apply_fillet_across(const Source& src, const SceneOperation& op, const Objects& objects,
                                               SceneBuild& out) {
  std::array<std::vector<fillet::SideFace>, 2> sides;
  for (std::size_t i = 0; i < 2; ++i)
    for (const auto& sf : op.sides[i]) {
      const std::string ptr = sf.pointer + "/cell";
      const vmodel::VCell& c = find_cell(src, objects, sf.cell, ptr);
      if (!c.plain())
        src.fail(ptr, quote(sf.cell) + " is a trimmed piece of a Boolean; expected a plain cell (fillets of "
                      "trimmed cells are later work)");
      if (c.volume.rational()) src.fail(ptr, quote(sf.cell) + " is rational; expected a polynomial cell");
      sides[i].push_back({&c.volume, sf.face, sf.cell + "/" + std::string(spline::face_name(sf.face))});
    }
  fillet::MultiFillet mf;
  try {
    mf = fillet::fillet_across(sides[0], sides[1], op.fillet, op.corners);
  } catch (const Error& e) {
    throw e.within(src.at(op.pointer));
  }
  std::vector<vmodel::VCell> cells;
  std::size_t k = 0;
  for (const auto& piece : mf.pieces) {
    FilletBuild rep;
    rep.name = op.name;
    rep.pointer = op.pointer;
    rep.cells = {op.sides[0][piece.face[0]].cell, op.sides[1][piece.face[1]].cell};
    rep.faces = {op.sides[0][piece.face[0]].face, op.sides[1][piece.face[1]].face};
    for (const auto& f : piece.fillets) {
      const auto& q = f.quality;
      const std::string base = op.name + "." + std::to_string(++k);
      if (q.jacobian() == "changes sign")
        throw Error(src.at(op.pointer) + ": fillet " + base + " between " + sides[0][piece.face[0]].name + " and " +
                        sides[1][piece.face[1]].name + ": det J changes sign inside (from " + format_double(q.det_min) +
                        " to " + format_double(q.det_max) + "); expected a io::valid fillet: try other distances or tau",
                    ErrorKind::failed);
      rep.cell_names.push_back({base + "a", base + "b"});
      rep.quality.push_back(q);
      for (std::size_t c = 0; c < 2; ++c) cells.push_back(f.vcell(c, rep.cell_names.back()[c]));
    }
    out.fillets.push_back(std::move(rep));
  }
  const auto piece_name = [&](const fillet::FilletPiece& p) {
    return sides[0][p.face[0]].name + " x " + sides[1][p.face[1]].name;
  };
  for (std::size_t j = 0; j < mf.corners.size(); ++j) {
    const auto& cf = mf.corners[j];
    const fillet::Junction& jn = mf.junctions[cf.junction];
    CornerBuild rep;
    rep.name = op.name;
    rep.pointer = op.pointer;
    const std::string base = op.name + ".c" + std::to_string(j + 1);
    rep.cell_names = {base + "a", base + "b"};
    rep.pieces = {piece_name(mf.pieces[jn.piece[0]]), piece_name(mf.pieces[jn.piece[1]])};
    const std::size_t g = static_cast<std::size_t>(jn.gap_side);
    // A bridge split at a seam (part 1: from the seam to q) lies on the leaving piece's faces.
    const fillet::FilletPiece& on = mf.pieces[jn.piece[cf.part == 1 ? 1 : 0]];
    rep.faces = {sides[g][on.face[g]].name, sides[1 - g][on.face[1 - g]].name};
    rep.part = cf.part;
    rep.junction = jn;
    rep.quality = cf.quality;
    if (cf.quality.jacobian() == "changes sign")
      throw Error(src.at(op.pointer) + ": the bridging fillet " + base + " at the corner (" + format_double(jn.o[0]) +
                      ", " + format_double(jn.o[1]) + ", " + format_double(jn.o[2]) + "): det J changes sign inside (from " +
                      format_double(cf.quality.det_min) + " to " + format_double(cf.quality.det_max) +
                      "); expected a io::valid fillet: try other distances or tau",
                  ErrorKind::failed);
    for (std::size_t c = 0; c < 2; ++c) cells.emplace_back(rep.cell_names[c], cf.cells[c]);
    out.corners.push_back(std::move(rep));
  }
  for (const auto& jn : mf.junctions) {
    if (jn.kind != fillet::JunctionKind::stitch) continue;
    StitchBuild rep;
    rep.name = op.name;
    rep.pointer = op.pointer;
    rep.pieces = {piece_name(mf.pieces[jn.piece[0]]), piece_name(mf.pieces[jn.piece[1]])};
    const std::size_t g = static_cast<std::size_t>(jn.gap_side);
    rep.faces = {sides[g][mf.pieces[jn.piece[0]].face[g]].name, sides[1 - g][mf.pieces[jn.piece[0]].face[1 - g]].name};
    rep.junction = jn;
    out.stitches.push_back(std::move(rep));
  }
  return cells;
}

/// Masalha et al. 2021, Alg. 2 (or Sec. 3.2 / Alg. 3 with "construction": "vbs", Sec. 5 / Alg. 6 with
/// "vrep") between two cells: the faces (given, or the one intersecting pair), the fillets, their
/// cells named <name>.<k>a and <name>.<k>b (vbs: <name>.<k>.1, .2, .3; vrep: the trimmed cell
/// <name>.<k>).
template <class Objects>
std::vector<vmodel::VCell> apply_fillet(const Source& src, const SceneOperation& op,
                                        const Objects& objects, SceneBuild& out) {
  if (op.across) return apply_fillet_across(src, op, objects, out);
  std::array<const vmodel::VCell*, 2> cell{};
  for (std::size_t i = 0; i < 2; ++i) {
    const std::string ptr = op.pointer + "/between/" + std::to_string(i);
    cell[i] = &find_cell(src, objects, op.between[i], ptr);
    if (!cell[i]->plain())
      src.fail(ptr, quote(op.between[i]) + " is a trimmed piece of a Boolean; expected a plain cell (fillets of "
                    "trimmed cells are later work)");
    if (cell[i]->volume.rational())
      src.fail(ptr, quote(op.between[i]) + " is rational; expected a polynomial cell");
  }
  if (op.bridge) {
    // Flends Sec. III: one cell from face to face (the reader made sure both faces are named).
    BridgeBuild rep;
    rep.name = op.name;
    rep.pointer = op.pointer;
    rep.cells = op.between;
    rep.faces = {*op.faces[0], *op.faces[1]};
    rep.cell_name = op.name + ".1";
    const auto start = std::chrono::steady_clock::now();
    spline::Trivariate t;
    try {
      t = fillet::bridge(cell[0]->volume, rep.faces[0], cell[1]->volume, rep.faces[1], {.dip = op.fillet.blend.dip},
                         &rep.quality);
    } catch (const Error& e) {
      throw e.within(src.at(op.pointer));
    }
    rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::vector<vmodel::VCell> cells;
    cells.emplace_back(rep.cell_name, std::move(t));
    out.bridges.push_back(std::move(rep));
    return cells;
  }
  std::array<spline::Face, 2> faces{};
  if (op.faces[0] && op.faces[1]) {
    faces = {*op.faces[0], *op.faces[1]};
  } else {
    // The pairs of faces that cross along a curve.
    geom::IntersectionOptions io;
    const auto b0 = spline::bounding_box(cell[0]->volume, 3), b1 = spline::bounding_box(cell[1]->volume, 3);
    double diag = 0.0;
    for (std::size_t j = 0; j < 3; ++j) {
      const double e = std::max(b0[1][j], b1[1][j]) - std::min(b0[0][j], b1[0][j]);
      diag += e * e;
    }
    io.tolerance = 1e-7 * std::sqrt(diag);
    std::vector<std::array<spline::Face, 2>> hits;
    for (spline::Face f0 : spline::all_faces) {
      if (op.faces[0] && f0 != *op.faces[0]) continue;
      const spline::Surface s0 = spline::boundary_face(cell[0]->volume, f0);
      for (spline::Face f1 : spline::all_faces) {
        if (op.faces[1] && f1 != *op.faces[1]) continue;
        const auto curves = geom::intersect_surfaces(s0, spline::boundary_face(cell[1]->volume, f1), io);
        const bool curve = std::any_of(curves.begin(), curves.end(), [](const auto& c) { return c.points.size() > 1; });
        if (curve) hits.push_back({f0, f1});
      }
    }
    const std::string names = quote(op.between[0]) + " and " + quote(op.between[1]);
    if (hits.empty())
      src.fail(op.pointer + "/between", "the faces of " + names + " do not intersect; expected cells whose "
                                        "boundaries cross along a curve");
    if (hits.size() > 1) {
      std::string list;
      for (const auto& h : hits)
        list += (list.empty() ? "" : ", ") + std::string(spline::face_name(h[0])) + "/" + std::string(spline::face_name(h[1]));
      src.fail(op.pointer + "/between", names + " intersect on several pairs of faces (" + list +
                                            "); expected one: choose the faces with {\"cell\", \"face\"} (fillets "
                                            "across several faces are later work)");
    }
    faces = hits.front();
  }
  std::vector<fillet::Fillet> fillets;
  try {
    fillets = fillet::fillet_faces(cell[0]->volume, faces[0], cell[1]->volume, faces[1], op.fillet);
  } catch (const Error& e) {
    throw e.within(src.at(op.pointer));
  }
  FilletBuild rep;
  rep.name = op.name;
  rep.pointer = op.pointer;
  rep.cells = op.between;
  rep.faces = faces;
  std::vector<vmodel::VCell> cells;
  for (std::size_t k = 0; k < fillets.size(); ++k) {
    const auto& q = fillets[k].quality;
    if (q.jacobian() == "changes sign")
      throw Error(src.at(op.pointer) + ": fillet " + std::to_string(k + 1) + " of " + quote(op.name) +
                      ": det J changes sign inside (from " + format_double(q.det_min) + " to " +
                      format_double(q.det_max) + "); expected a io::valid fillet: try other distances or tau",
                  ErrorKind::failed);
    const std::string base = op.name + "." + std::to_string(k + 1);
    // Ruled (Alg. 2): the halves <base>a, <base>b; VBS (Alg. 3): T_1, T_2, T_3 as <base>.1 .. .3;
    // V-rep (Alg. 6): the trimmed cell <base> (its trimming solid <base>.beyond.1, .2).
    std::vector<std::string> names;
    if (q.construction == fillet::Construction::vbs)
      names = {base + ".1", base + ".2", base + ".3"};
    else if (q.construction == fillet::Construction::vrep)
      names = {base};
    else
      names = {base + "a", base + "b"};
    rep.cell_names.push_back(names);
    rep.quality.push_back(q);
    if (!op.shepard) {
      for (std::size_t c = 0; c < names.size(); ++c) cells.push_back(fillets[k].vcell(c, names[c]));
      continue;
    }
    // Masalha et al. 2021, Sec. 7.2: both halves carry f, encoded, and S^_1, S^_2 (their faces w = 0) for
    // the exact per-voxel value.
    vmodel::ShepardData sd;
    sd.power = op.shepard_power;
    for (std::size_t h = 0; h < 2; ++h) sd.sources[h] = spline::boundary_face(fillets[k].cells[h], spline::Face::w0);
    const vmodel::ShepardField field(sd);
    for (std::size_t h = 0; h < 2; ++h) {
      auto enc = fillet::encode_shepard(fillets[k].cells[h], field, {.power = op.shepard_power});
      rep.shepard.push_back({enc.max_error, enc.rms_error, enc.check_error, enc.samples, enc.seconds});
      cells.emplace_back(base + (h == 0 ? "a" : "b"), std::move(enc.half));
    }
    // The sources as the encoded halves' faces w = 0 (the same surfaces, refined across C): the
    // encoded properties there are then the sources' g_i, control point for control point.
    for (std::size_t h = 0; h < 2; ++h)
      sd.sources[h] = spline::boundary_face(cells[cells.size() - 2 + h].volume, spline::Face::w0);
    for (std::size_t h = 0; h < 2; ++h) cells[cells.size() - 2 + h].shepard = sd;
  }
  out.fillets.push_back(std::move(rep));
  return cells;
}

/// The scene's Boolean and fillet operations, in order, on named objects: each scene cell (a
/// primitive's cells together) is an object; a Boolean replaces its operands by its result,
/// placed where `a` was; a fillet appends its cells as a new object. The primitives' reports keep
/// only the primitives no Boolean consumed.
void apply_operations(const Scene& scene, const Source& src, SceneBuild& out) {
  struct Object {
    std::string name;
    std::vector<vmodel::VCell> cells;
    int primitive = -1;  ///< index into out.primitives, -1 for a result or a trivariate cell
  };
  std::vector<Object> objects;
  std::size_t next = 0;
  for (const SceneCell& cell : scene.cells) {
    Object o;
    o.name = cell.name;
    int count = 1;
    for (std::size_t p = 0; p < out.primitives.size(); ++p)
      if (out.primitives[p].name == cell.name) {
        o.primitive = static_cast<int>(p);
        count = out.primitives[p].cell_count;
      }
    for (int k = 0; k < count; ++k) o.cells.push_back(std::move(out.model.cells[next++]));
    objects.push_back(std::move(o));
  }
  std::optional<std::map<std::string, spline::Surface>> surfaces;  // resolved at the first constructor
  const auto find_object = [&](const std::string& name) {
    return std::find_if(objects.begin(), objects.end(), [&](const Object& o) { return o.name == name; });
  };
  for (const SceneOperation& op : scene.operations) {
    if (detail::is_constructor(op.op)) {
      if (find_object(op.name) != objects.end())
        src.fail(op.pointer + "/name", quote(op.name) + " names another cell or result; expected a fresh name");
      if (!surfaces) surfaces = detail::resolve_surfaces(scene, src, out);
      objects.push_back({op.name, detail::apply_constructor(scene, src, op, *surfaces, out), -1});
      continue;
    }
    if (op.op == "fillet") {
      if (find_object(op.name) != objects.end())
        src.fail(op.pointer + "/name", quote(op.name) + " names another cell or result; expected a fresh name");
      Object result{op.name, apply_fillet(src, op, objects, out), -1};
      objects.push_back(std::move(result));
      continue;
    }
    const auto ia = find_object(op.a);
    if (ia == objects.end())
      src.fail(op.pointer + "/a", "no cell or result named " + quote(op.a) + "; expected the name of a scene cell or of an earlier operation's result");
    const auto ib = find_object(op.b);
    if (ib == objects.end())
      src.fail(op.pointer + "/b", "no cell or result named " + quote(op.b) + "; expected the name of a scene cell or of an earlier operation's result");
    if (ia == ib) src.fail(op.pointer + "/b", quote(op.b) + " is also \"a\"; expected two different operands");
    if (op.name != op.a && op.name != op.b && find_object(op.name) != objects.end())
      src.fail(op.pointer + "/name", quote(op.name) + " names another cell or result; expected a fresh name");
    vmodel::VModel A, B;
    A.units = B.units = scene.units;
    A.properties = B.properties = scene.properties;
    A.cells = ia->cells;
    B.cells = ib->cells;
    const vmodel::BooleanOp kind = op.op == "union" ? vmodel::BooleanOp::union_op
                                   : op.op == "intersection" ? vmodel::BooleanOp::intersection
                                                             : vmodel::BooleanOp::subtraction;
    vmodel::VModel r;
    try {
      r = slice::untrim(vmodel::boolean(A, B, kind, {.blend = op.blend, .power = op.power}));
    } catch (const Error& e) {
      throw e.within(src.at(op.pointer));
    }
    if (r.cells.empty())
      src.fail(op.pointer, "the " + op.op + " of " + quote(op.a) + " and " + quote(op.b) +
                               " is empty (their boxes do not meet); expected operands that overlap");
    Object result{op.name, std::move(r.cells), -1};
    const std::size_t at = static_cast<std::size_t>(ia - objects.begin());
    const std::size_t bt = static_cast<std::size_t>(ib - objects.begin());
    objects[at] = std::move(result);
    objects.erase(objects.begin() + static_cast<std::ptrdiff_t>(bt));
  }
  // The model: the remaining objects in order; reports for the untouched primitives.
  std::vector<PrimitiveBuild> kept;
  out.model.cells.clear();
  std::map<std::string, std::string> names;
  for (auto& o : objects) {
    if (o.primitive >= 0) {
      PrimitiveBuild rep = std::move(out.primitives[static_cast<std::size_t>(o.primitive)]);
      rep.first_cell = static_cast<int>(out.model.cells.size());
      kept.push_back(std::move(rep));
    }
    for (auto& c : o.cells) {
      if (!names.emplace(c.name, o.name).second)
        src.fail("/operations", "the result has two cells named " + quote(c.name) + "; expected distinct cell names "
                                "(rename a scene cell)");
      out.model.cells.push_back(std::move(c));
    }
  }
  out.primitives = std::move(kept);
}

}  // namespace

construct::Field detail::read_field(const Source& src, const json& j, const std::string& ptr, std::size_t properties) {
  return scene::read_field(src, j, ptr, properties);
}

Scene read_scene_json(std::string_view text, const std::string& source) {
  const Source src{source};
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

Scene load_scene(const std::filesystem::path& path) { return read_scene_json(io::read_file(path), path.string()); }

SceneBuild build_scene(const Scene& scene) {
  const Source src{scene.source};
  for (const SceneOperation& op : scene.operations) {
    const bool boolean = op.op == "union" || op.op == "intersection" || op.op == "subtraction";
    if (boolean || op.op == "fillet" || detail::is_constructor(op.op)) continue;
    src.fail(op.pointer + "/op",
             quote(op.op) + " is not supported yet in scenes (`trivox construct` runs it on its own); expected "
                 "union, intersection, subtraction, fillet, ruled, boolean_sum, half_boolean_sum, extrude, revolve or sweep");
  }
  SceneBuild out;
  out.model.units = scene.units;
  out.model.properties = scene.properties;
  out.model.surfaces = scene.surfaces;
  std::map<std::string, std::string> owner;  // model cell name -> scene pointer
  auto add = [&](std::string name, spline::Trivariate volume, const SceneCell& from) {
    const auto [it, fresh] = owner.emplace(name, from.pointer);
    if (!fresh)
      src.fail(from.pointer + "/name", "cell " + quote(name) + " (from " + quote(from.name) + ") is also a cell of " +
                                           it->second + "; expected unique cell names (a primitive's cells are "
                                           "named <name>.<part>)");
    out.model.cells.push_back({std::move(name), std::move(volume)});
  };
  for (const auto& s : scene.surfaces) owner.emplace(s.name, "/surfaces");
  for (const SceneCell& cell : scene.cells) {
    if (const auto* t = std::get_if<spline::Trivariate>(&cell.content)) {
      add(cell.name, *t, cell);
      continue;
    }
    const auto& p = std::get<ScenePrimitive>(cell.content);
    PrimitiveBuild report;
    report.name = cell.name;
    report.type = construct::primitive_type(p.primitive);
    report.first_cell = static_cast<int>(out.model.cells.size());
    report.exact_volume = construct::exact_volume(p.primitive);
    try {
      auto cells = construct::build_primitive(cell.name, p.primitive, p.options);
      for (const auto& c : cells) report.geometry.push_back(c.volume);
      if (p.field) {
        report.has_field = true;
        report.field = construct::apply_field(cells, *p.field);
      }
      report.cell_count = static_cast<int>(cells.size());
      for (auto& c : cells) add(std::move(c.name), std::move(c.volume), cell);
    } catch (const Error& e) {
      if (std::string_view(e.what()).starts_with(scene.source + ": ")) throw;
      throw e.within(src.at(cell.pointer));
    }
    out.primitives.push_back(std::move(report));
  }
  if (!scene.operations.empty()) apply_operations(scene, src, out);
  return out;
}

}  // namespace trivox::scene
