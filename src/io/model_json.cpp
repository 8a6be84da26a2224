#include "trivox/io/model_json.hpp"

#include <tbb/parallel_for.h>

#include <array>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <exception>
#include <map>
#include <optional>
#include <nlohmann/json.hpp>

#include "json_io.hpp"
#include "model_scan.hpp"
#include "trivox/spline/extract.hpp"

#include "trivox/error.hpp"

namespace trivox::io {

namespace {

constexpr std::array<std::string_view, 5> units_list = {"um", "mm", "cm", "m", "in"};

using namespace json_io;

// ------------------------------------------------------------------------------------------
// The model

constexpr const char* scene_message =
    "this is a scene (primitives/operations); expected a model, whose cells are all "
    "trivariates: run `trivox build SCENE -o MODEL` to turn the scene into one";

/// Scenes are recognised before anything else so that they get the `build` hint, not a
/// complaint about a missing trivariate.
void reject_scene(const Source& src, const json& root) {
  if (const json* ops = find(root, "operations")) {
    expect_array(src, *ops, "/operations", "an array of operations (empty in a model)");
    if (!ops->empty()) src.fail("/operations", scene_message);
  }
  const json* cells = find(root, "cells");
  if (cells == nullptr || !cells->is_array()) return;
  for (std::size_t i = 0; i < cells->size(); ++i)
    if ((*cells)[i].is_object() && (*cells)[i].contains("primitive"))
      src.fail(child(child("/cells", i), "primitive"), scene_message);
}

vmodel::VCell read_cell(const Source& src, const json& item, const std::string& ip, const PointShape& shape,
                        NameTable& names, int depth);

/// A trimmed cell's "within" (cell objects), "without" (arrays of cell objects) and "blend"
/// (vmodel::VCell; written by Boolean operations).
void read_trims(const Source& src, const json& item, const std::string& ip, const PointShape& shape,
                vmodel::VCell& cell, int depth) {
  if (depth > 64) src.fail(ip, "Boolean trimming nested more than 64 deep; expected a shallower model");
  const std::string cell_what = "a cell object {\"name\", \"trivariate\"}";
  if (const json* w = find(item, "within")) {
    const std::string wp = child(ip, "within");
    expect_array(src, *w, wp, "an array of " + cell_what + " objects");
    NameTable local;
    for (std::size_t i = 0; i < w->size(); ++i) cell.within.push_back(read_cell(src, (*w)[i], child(wp, i), shape, local, depth + 1));
  }
  if (const json* o = find(item, "without")) {
    const std::string op = child(ip, "without");
    expect_array(src, *o, op, "an array of solids, each an array of " + cell_what + " objects");
    for (std::size_t i = 0; i < o->size(); ++i) {
      const std::string sp = child(op, i);
      expect_array(src, (*o)[i], sp, "a solid: an array of " + cell_what + " objects");
      std::vector<vmodel::VCell> solid;
      NameTable local;
      for (std::size_t k = 0; k < (*o)[i].size(); ++k)
        solid.push_back(read_cell(src, (*o)[i][k], child(sp, k), shape, local, depth + 1));
      cell.without.push_back(std::move(solid));
    }
  }
  if (const json* b = find(item, "blend")) {
    const std::string expected = "a blend rule: \"first\", \"sum_clip\", \"mean\" or \"distance\"";
    const std::string name = read_string(src, *b, child(ip, "blend"), expected);
    if (!vmodel::blend_rule_from_name(name, cell.blend))
      src.fail(child(ip, "blend"), "unknown blend rule " + quote(name) + "; expected " + expected);
  }
  if (const json* k = find(item, "blend_power")) {
    cell.blend_power = read_number(src, *k, child(ip, "blend_power"));
    if (!(cell.blend_power > 0))
      src.fail(child(ip, "blend_power"), "power " + format_double(cell.blend_power) + "; expected a positive power");
  }
  if (const json* tc = find(item, "trim_curves")) {
    const std::string tp = child(ip, "trim_curves");
    const std::string what = "{\"face\": u0|u1|v0|v1|w0|w1, \"curves\": [curves in the face's parameters]}";
    expect_array(src, *tc, tp, "an array of " + what);
    for (std::size_t i = 0; i < tc->size(); ++i) {
      const std::string fp = child(tp, i);
      const json& f = expect_object(src, (*tc)[i], fp, what);
      vmodel::FaceTrim t;
      const std::string face = read_string(src, require(src, f, fp, "face", what), child(fp, "face"), "a face name u0 u1 v0 v1 w0 w1");
      try {
        t.face = spline::face_from_name(face);
      } catch (const Error&) {
        src.fail(child(fp, "face"), "unknown face " + quote(face) + "; expected u0, u1, v0, v1, w0 or w1");
      }
      const std::string cp = child(fp, "curves");
      const json& cs = expect_array(src, require(src, f, fp, "curves", what), cp, "an array of curves {\"orders\", \"knots\", \"points\"} in R^2");
      for (std::size_t k = 0; k < cs.size(); ++k) t.curves.push_back(read_spline<1>(src, cs[k], child(cp, k), PointShape{2, "2 (the face's parameters)"}));
      cell.trim_curves.push_back(std::move(t));
    }
  }
  if (const json* b = find(item, "boundaries")) {
    const std::string bp = child(ip, "boundaries");
    const std::string list_what = "an array of boundary surfaces, each {\"orders\", \"knots\", \"points\"} in xyz";
    expect_array(src, *b, bp, "one " + list_what.substr(3) + " per blended value");
    for (std::size_t i = 0; i < b->size(); ++i) {
      const std::string lp = child(bp, i);
      expect_array(src, (*b)[i], lp, list_what);
      std::vector<spline::Surface> list;
      for (std::size_t k = 0; k < (*b)[i].size(); ++k)
        list.push_back(read_spline<2>(src, (*b)[i][k], child(lp, k), PointShape{3, "3 (xyz)"}));
      cell.boundaries.push_back(std::move(list));
    }
  }
}

/// A Shepard fillet cell's "shepard": {"power": q, "surfaces": [S^_1, S^_2]} (vmodel::ShepardData;
/// written by fillets built with "blend": "shepard"), surfaces in R^(3+m) like the cells.
void read_shepard(const Source& src, const json& item, const std::string& ip, const PointShape& shape,
                  vmodel::VCell& cell) {
  const json* j = find(item, "shepard");
  if (j == nullptr) return;
  const std::string sp = child(ip, "shepard");
  const std::string what = "{\"power\": q, \"surfaces\": [S1, S2]}";
  const json& o = expect_object(src, *j, sp, "a Shepard blend " + what);
  vmodel::ShepardData d;
  d.power = read_int(src, require(src, o, sp, "power", what), child(sp, "power"), 1, 16, "a power q, an integer in 1..16");
  const std::string lp = child(sp, "surfaces");
  const json& list = require(src, o, sp, "surfaces", what);
  if (!list.is_array() || list.size() != 2)
    src.fail(lp, describe(list) + "; expected an array of two surfaces {\"orders\", \"knots\", \"points\"} (S^_1, S^_2)");
  for (std::size_t i = 0; i < 2; ++i) d.sources[i] = read_spline<2>(src, list[i], child(lp, i), shape);
  cell.shepard = std::move(d);
}

vmodel::VCell read_cell(const Source& src, const json& item_in, const std::string& ip, const PointShape& shape,
                        NameTable& names, int depth) {
  const std::string what = "{\"name\", \"trivariate\"}";
  const json& item = expect_object(src, item_in, ip, "an object " + what);
  std::string name = read_name(src, item, ip, names);
  vmodel::VCell cell(std::move(name),
                     read_spline<3>(src, require(src, item, ip, "trivariate", what), child(ip, "trivariate"), shape));
  read_trims(src, item, ip, shape, cell, depth);
  read_shepard(src, item, ip, shape, cell);
  return cell;
}

/// One array of named splines: "cells" (key "trivariate") or "surfaces" (key "surface").
template <int P, class Item>
std::vector<Item> read_items(const Source& src, const json& root, const char* list, const char* key,
                             const PointShape& shape, NameTable& names) {
  const json* j = find(root, list);
  if (j == nullptr) return {};
  const std::string lp = std::string("/") + list;
  const std::string what = std::string("{\"name\", \"") + key + "\"}";
  expect_array(src, *j, lp, "an array of " + what + " objects");
  // Items in parallel (a thousand-span cell's points take a while), with the serial reading's
  // errors: each item's object and name first, in order (the names must be unique), then its
  // spline, trims and Shepard data; the error reported is that of the first item, in order, that
  // has one, and within it the first the serial reading would meet.
  const std::size_t n = j->size();
  std::vector<std::optional<Item>> out(n);
  std::vector<std::exception_ptr> error(n);
  std::size_t named = n;  // items before the first object or name error
  for (std::size_t i = 0; i < n && named == n; ++i) {
    try {
      const std::string ip = child(lp, i);
      const json& item = expect_object(src, (*j)[i], ip, "an object " + what);
      out[i].emplace();
      out[i]->name = read_name(src, item, ip, names);
    } catch (...) {
      error[i] = std::current_exception();
      named = i;
    }
  }
  tbb::parallel_for(std::size_t{0}, std::min(named, n), [&](std::size_t i) {
    try {
      const std::string ip = child(lp, i);
      const json& item = (*j)[i];
      Item& it = *out[i];
      it = Item{std::move(it.name), read_spline<P>(src, require(src, item, ip, key, what), child(ip, key), shape)};
      if constexpr (P == 3) {
        read_trims(src, item, ip, shape, it, 0);
        read_shepard(src, item, ip, shape, it);
      }
    } catch (...) {
      error[i] = std::current_exception();
    }
  });
  for (std::size_t i = 0; i < n; ++i)
    if (error[i]) std::rethrow_exception(error[i]);
  std::vector<Item> items;
  items.reserve(n);
  for (auto& it : out) items.push_back(std::move(*it));
  return items;
}

// ------------------------------------------------------------------------------------------
// Writing

constexpr const char* cannot_write = "cannot write the model: ";

/// The header checks of check_writable: content, units and property names.
void check_header(const vmodel::VModel& m) {
  if (m.cells.empty() && m.surfaces.empty())
    throw Error(std::string(cannot_write) + "no cells and no surfaces; expected at least one");
  if (!known_units(m.units))
    throw Error(cannot_write + ("unknown units " + quote(m.units)) +
                "; expected um, mm, cm, m or in");
  for (std::size_t i = 0; i < m.properties.size(); ++i)
    for (std::size_t k = 0; k <= i; ++k)
      if (m.properties[i].empty() || (k < i && m.properties[k] == m.properties[i]))
        throw Error(cannot_write + ("property " + std::to_string(i)) + " is " +
                    quote(m.properties[i]) + "; expected unique non-empty names");
}

/// One cell or surface: a fresh name, the model's dimension, finite values.
template <int P>
void check_item(const std::string& name, const spline::TensorSpline<P>& s, const PointShape& shape,
                NameTable& names) {
  const std::string pre = cannot_write + quote(name);
  if (name.empty() || !names.emplace(name, "").second)
    throw Error(cannot_write + ("name " + quote(name)) + "; expected unique non-empty names");
  if (s.dim() != shape.dim)
    throw Error(pre + " has " + plural(s.dim(), "coordinate") + " per control point; expected " +
                shape.text);
  for (double v : s.points())
    if (!std::isfinite(v))
      throw Error(pre + " has a non-finite coordinate; expected finite numbers");
  for (double w : s.weights())
    if (!(w > 0) || !std::isfinite(w))
      throw Error(pre + " has weight " + format_double(w) + "; expected positive finite weights");
}

/// A trimmed cell's nested cells (names unique within each list, as the reader wants).
void check_trims(const vmodel::VCell& c, const PointShape& shape) {
  if (!(c.blend_power > 0) || !std::isfinite(c.blend_power))
    throw Error(cannot_write + quote(c.name) + " has blend power " + format_double(c.blend_power) +
                "; expected a positive power");
  for (const auto& t : c.trim_curves)
    for (const auto& k : t.curves)
      if (k.dim() != 2)
        throw Error(cannot_write + quote(c.name) + " has a trimming curve with " + plural(k.dim(), "coordinate") +
                    "; expected 2 (the face's parameters)");
  for (const auto& list : c.boundaries)
    for (const auto& f : list) {
      if (f.dim() != 3)
        throw Error(cannot_write + quote(c.name) + " has a boundary surface with " + plural(f.dim(), "coordinate") +
                    "; expected 3 (xyz)");
      for (double v : f.points())
        if (!std::isfinite(v)) throw Error(cannot_write + quote(c.name) + " has a non-finite boundary; expected finite numbers");
    }
  if (c.shepard) {
    if (c.shepard->power < 1 || c.shepard->power > 16)
      throw Error(cannot_write + quote(c.name) + " has Shepard power " + std::to_string(c.shepard->power) +
                  "; expected an integer in 1..16");
    for (const auto& f : c.shepard->sources) {
      if (f.dim() != shape.dim)
        throw Error(cannot_write + quote(c.name) + " has a Shepard surface with " + plural(f.dim(), "coordinate") +
                    "; expected " + shape.text);
      for (double v : f.points())
        if (!std::isfinite(v)) throw Error(cannot_write + quote(c.name) + " has a non-finite Shepard surface; expected finite numbers");
      for (double w : f.weights())
        if (!(w > 0) || !std::isfinite(w))
          throw Error(cannot_write + quote(c.name) + " has a Shepard surface weight " + format_double(w) + "; expected positive finite weights");
    }
  }
  NameTable within;
  for (const auto& w : c.within) {
    check_item(w.name, w.volume, shape, within);
    check_trims(w, shape);
  }
  for (const auto& solid : c.without) {
    NameTable local;
    for (const auto& o : solid) {
      check_item(o.name, o.volume, shape, local);
      check_trims(o, shape);
    }
  }
}

/// Everything the reader would reject, checked before a byte is written.
void check_writable(const vmodel::VModel& m) {
  check_header(m);
  const PointShape shape = point_shape(m.properties.size());
  NameTable names;
  for (const auto& c : m.cells) {
    check_item(c.name, c.volume, shape, names);
    check_trims(c, shape);
  }
  for (const auto& s : m.surfaces) check_item(s.name, s.surface, shape, names);
}

/// "[x0, x1, ...]" with each element written by `write`.
template <class Items, class Write>
void write_list(std::string& out, const Items& items, Write write) {
  out += '[';
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i) out += ", ";
    write(items[i]);
  }
  out += ']';
}

/// A cell object at the given indentation, with its trimming (nested cells) when it has any.
void write_cell(std::string& out, const vmodel::VCell& c, const std::string& indent) {
  const std::string in1 = indent + "  ";
  const auto cell = [&](const vmodel::VCell& x) { write_cell(out, x, in1); };
  const auto spline = [&](const auto& x) { write_spline(out, x, in1); };
  out += "{\n" + in1 + "\"name\": " + quote(c.name) + ",\n" + in1 + "\"trivariate\": ";
  write_spline(out, c.volume, in1);
  if (!c.within.empty()) {
    out += ",\n" + in1 + "\"within\": ";
    write_list(out, c.within, cell);
  }
  if (!c.without.empty()) {
    out += ",\n" + in1 + "\"without\": ";
    write_list(out, c.without, [&](const std::vector<vmodel::VCell>& solid) { write_list(out, solid, cell); });
  }
  if (c.blend != vmodel::BlendRule::first) out += ",\n" + in1 + "\"blend\": " + quote(vmodel::blend_rule_name(c.blend));
  if (c.blend_power != 1.0) out += ",\n" + in1 + "\"blend_power\": " + format_double(c.blend_power);
  if (!c.trim_curves.empty()) {
    out += ",\n" + in1 + "\"trim_curves\": ";
    write_list(out, c.trim_curves, [&](const vmodel::FaceTrim& t) {
      out += "{\"face\": " + quote(std::string(spline::face_name(t.face))) + ", \"curves\": ";
      write_list(out, t.curves, spline);
      out += "}";
    });
  }
  if (!c.boundaries.empty()) {
    out += ",\n" + in1 + "\"boundaries\": ";
    write_list(out, c.boundaries, [&](const std::vector<spline::Surface>& list) { write_list(out, list, spline); });
  }
  if (c.shepard) {
    out += ",\n" + in1 + "\"shepard\": {\"power\": " + std::to_string(c.shepard->power) + ", \"surfaces\": ";
    write_list(out, c.shepard->sources, spline);
    out += "}";
  }
  out += "\n" + indent + "}";
}

template <class Item, class Get>
void write_items(std::string& out, const std::vector<Item>& items, const char* list,
                 const char* key, Get get) {
  out += std::string("  \"") + list + "\": [";
  for (std::size_t i = 0; i < items.size(); ++i) {
    out += (i ? ",\n" : "\n");
    out += "    {\n      \"name\": " + quote(items[i].name) + ",\n      \"" + key + "\": ";
    write_spline(out, get(items[i]), "      ");
    out += "\n    }";
  }
  out += items.empty() ? "],\n" : "\n  ],\n";
}

}  // namespace

bool known_units(std::string_view units) noexcept {
  for (auto u : units_list)
    if (u == units) return true;
  return false;
}

vmodel::VModel read_model_json(std::string_view text, const std::string& source, const Limits& limits) {
  const Source src{source};
  scan_model_json(text, source, limits);  // limits and counts before the tree is built
  const json root = parse(src, text);
  expect_object(src, root, "", "a trivox model object {\"trivox\": 1, ...}");
  check_version(src, root);
  reject_scene(src, root);
  vmodel::VModel model;
  model.units = read_units(src, root);
  model.properties = read_properties(src, root);
  const PointShape shape = point_shape(model.properties.size());
  NameTable names;
  model.cells = read_items<3, vmodel::VCell>(src, root, "cells", "trivariate", shape, names);
  model.surfaces =
      read_items<2, vmodel::NamedSurface>(src, root, "surfaces", "surface", shape, names);
  if (model.cells.empty() && model.surfaces.empty())
    src.fail("",
             "no cells and no surfaces; expected at least one cell (\"cells\") or "
             "surface (\"surfaces\")");
  return model;
}

std::string write_model_json(const vmodel::VModel& model) {
  check_writable(model);
  std::string out = "{\n  \"trivox\": " + std::to_string(model_format_version) +
                    ",\n  \"units\": " + quote(model.units) + ",\n  \"properties\": [";
  for (std::size_t i = 0; i < model.properties.size(); ++i)
    out += (i ? ", " : "") + quote(model.properties[i]);
  out += "],\n";
  out += "  \"cells\": [";
  for (std::size_t i = 0; i < model.cells.size(); ++i) {
    out += (i ? ",\n    " : "\n    ");
    write_cell(out, model.cells[i], "    ");
  }
  out += model.cells.empty() ? "],\n" : "\n  ],\n";
  if (!model.surfaces.empty())
    write_items(out, model.surfaces, "surfaces", "surface",
                [](const vmodel::NamedSurface& s) -> const spline::Surface& { return s.surface; });
  out += "  \"operations\": []\n}\n";
  return out;
}

}  // namespace trivox::io
