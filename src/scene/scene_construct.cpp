// Scene surfaces from G+Smo patches and offsets, and the constructor operations (scene_construct.hpp).
#include "scene_construct.hpp"

#include <chrono>
#include <filesystem>
#include <numbers>

#include "trivox/construct/constructors.hpp"
#include "trivox/construct/tube_solid.hpp"
#include "trivox/error.hpp"
#include "trivox/io/gismo_xml.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::scene::detail {

using namespace io::json_io;
using spline::Surface;

namespace {

constexpr const char* constructor_ops[] = {"ruled", "boolean_sum", "half_boolean_sum", "extrude", "revolve", "sweep"};

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

/// [a, b] with a < b, both finite.
std::array<double, 2> read_interval(const Source& src, const json& j, const std::string& ptr, const std::string& what) {
  if (!j.is_array() || j.size() != 2) fail_type(src, ptr, j, what);
  const double a = read_number_at(src, j[0], ptr, 0), b = read_number_at(src, j[1], ptr, 1);
  if (!(a < b)) src.fail(ptr, "[" + format_double(a) + ", " + format_double(b) + "]; expected " + what);
  return {a, b};
}

/// "patches": [i, ...] (one row) or [[i, ...], ...] (rows along v, each along u).
void read_patch_grid(const Source& src, const json& j, const std::string& ptr, SceneSurfaceRecipe& r) {
  const std::string what = "patch indices: [i, ...] (one row along u) or [[i, ...], ...] (rows along v, equal lengths)";
  if (!j.is_array() || j.empty()) fail_type(src, ptr, j, what);
  const bool rows = j[0].is_array();
  const std::size_t n_rows = rows ? j.size() : 1;
  for (std::size_t row = 0; row < n_rows; ++row) {
    const std::string rp = rows ? child(ptr, row) : ptr;
    const json& line = rows ? j[row] : j;
    if (!line.is_array() || line.empty()) fail_type(src, rp, line, what);
    if (row == 0) r.grid[0] = static_cast<int>(line.size());
    if (static_cast<int>(line.size()) != r.grid[0])
      src.fail(rp, std::to_string(line.size()) + (line.size() == 1 ? " patch" : " patches") + "; expected " +
                       std::to_string(r.grid[0]) + " as in the first row (" + what + ")");
    for (std::size_t i = 0; i < line.size(); ++i)
      r.patches.push_back(read_int(src, line[i], child(rp, i), 0, 1 << 20, "a patch index (0-based, in file order)"));
  }
  r.grid[1] = static_cast<int>(n_rows);
}

/// The patches of the G+Smo file merged, scaled, translated and restricted as the object says.
void load_gismo(const Source& src, const json& item, const std::string& ptr, SceneSurfaceRecipe& r) {
  const std::string gp = child(ptr, "gismo");
  r.file = read_string(src, item["gismo"], gp, "a G+Smo file name (relative to the scene's folder)");
  if (r.file.empty()) src.fail(gp, "empty file name; expected a G+Smo file name (relative to the scene's folder)");
  const std::string what = "a G+Smo surface {\"name\", \"gismo\": FILE, \"patches\", \"scale\", \"translate\", \"u\", \"v\"}";
  read_patch_grid(src, require(src, item, ptr, "patches", what), child(ptr, "patches"), r);
  std::array<double, 3> scale{1, 1, 1}, shift{0, 0, 0};
  if (const json* s = find(item, "scale")) {
    const std::string sp = child(ptr, "scale");
    if (s->is_number()) {
      scale.fill(read_number(src, *s, sp));
    } else if (s->is_array() && s->size() == 3) {
      for (std::size_t c = 0; c < 3; ++c) scale[c] = read_number_at(src, (*s)[c], sp, c);
    } else {
      fail_type(src, sp, *s, "a scale factor, or [sx, sy, sz]");
    }
    for (double f : scale)
      if (!(f > 0.0)) src.fail(sp, "scale " + format_double(f) + "; expected positive scale factors");
  }
  if (const json* t = find(item, "translate")) {
    const std::string tp = child(ptr, "translate");
    if (!t->is_array() || t->size() != 3) fail_type(src, tp, *t, "a vector [x, y, z]");
    for (std::size_t c = 0; c < 3; ++c) shift[c] = read_number_at(src, (*t)[c], tp, c);
  }
  const std::filesystem::path path = std::filesystem::path(src.name).parent_path() / r.file;
  vmodel::VModel file;
  try {
    file = io::read_gismo_xml(io::read_file(path, default_limits()), path.string());
  } catch (const Error& e) {
    throw e.within(src.at(gp));
  }
  // Geometry i is the surface "patch<i>" (io/gismo_xml.hpp).
  std::vector<Surface> patches;
  for (std::size_t k = 0; k < r.patches.size(); ++k) {
    const std::string pname = "patch" + std::to_string(r.patches[k]);
    const auto it = std::find_if(file.surfaces.begin(), file.surfaces.end(),
                                 [&](const vmodel::NamedSurface& s) { return s.name == pname; });
    if (it == file.surfaces.end()) {
      const bool cell = std::any_of(file.cells.begin(), file.cells.end(), [&](const auto& c) { return c.name == pname; });
      src.fail(child(ptr, "patches"), "patch " + std::to_string(r.patches[k]) + " of " + r.file + " is " +
                                          (cell ? "a trivariate" : "not in the file (it has " +
                                                                       std::to_string(file.surfaces.size() + file.cells.size()) +
                                                                       " geometries)") +
                                          "; expected the index of a surface patch (TensorBSpline2)");
    }
    // xyz only: properties come from the constructors' fields.
    const Surface& s = it->surface;
    std::vector<double> pts;
    for (int row = 0; row < s.size(); ++row)
      for (std::size_t c = 0; c < 3; ++c) pts.push_back(scale[c] * s.point(row)[c] + shift[c]);
    patches.emplace_back(s.knot_vectors(), 3, std::move(pts), s.weights());
  }
  double extent = 0.0;
  for (const auto& p : patches) {
    const auto box = p.control_box();
    for (std::size_t c = 0; c < 3; ++c) extent = std::max(extent, box[1][c] - box[0][c]);
  }
  construct::MergeReport mr;
  Surface merged;
  try {
    merged = construct::merge_patches(patches, r.grid[0], 1e-9 * std::max(extent, 1.0), &mr);
  } catch (const Error& e) {
    // Name the patches by their indices in the file, not by grid position only.
    throw e.within(src.at(child(ptr, "patches")) + " (patches of " + r.file + " in rows of " + std::to_string(r.grid[0]) + ")");
  }
  r.max_gap = mr.max_gap;
  for (int d = 0; d < 2; ++d) {
    const char* key = d == 0 ? "u" : "v";
    const json* iv = find(item, key);
    if (!iv) continue;
    const std::string ip = child(ptr, key);
    const double hi = r.grid[static_cast<std::size_t>(d)];
    const std::string expected = std::string("a parameter interval [a, b] within [0, ") + format_double(hi) +
                                 "] (patch k spans [k, k+1] in " + key + ")";
    const auto [a, b] = read_interval(src, *iv, ip, expected);
    if (!(a >= 0.0 && b <= hi)) src.fail(ip, "[" + format_double(a) + ", " + format_double(b) + "]; expected " + expected);
    merged = spline::restrict_to(merged, d, a, b);
  }
  r.merged = std::move(merged);
}

void read_offset(const Source& src, const json& item, const std::string& ptr, SceneSurfaceRecipe& r) {
  const std::string op = child(ptr, "offset");
  const std::string what = "an offset {\"surface\": NAME, \"distance\": d, \"tolerance\": t}";
  const json& o = expect_object(src, item["offset"], op, what);
  r.of = read_string(src, require(src, o, op, "surface", what), child(op, "surface"), "the name of an earlier scene surface");
  r.distance = read_number(src, require(src, o, op, "distance", what), child(op, "distance"));
  if (r.distance == 0.0)
    src.fail(child(op, "distance"), "distance 0; expected a non-zero distance along S_u x S_v (negative: the other side)");
  r.offset.tolerance = 1e-3 * std::abs(r.distance);
  if (const json* t = find(o, "tolerance")) {
    r.offset.tolerance = read_number(src, *t, child(op, "tolerance"));
    if (!(r.offset.tolerance > 0.0 && r.offset.tolerance < std::abs(r.distance)))
      src.fail(child(op, "tolerance"), "tolerance " + format_double(r.offset.tolerance) +
                                           "; expected a positive tolerance below |distance| (model units)");
  }
}

const Surface& surface_named(const Source& src, const std::map<std::string, Surface>& surfaces, const std::string& name,
                             const std::string& ptr) {
  const auto it = surfaces.find(name);
  if (it == surfaces.end())
    src.fail(ptr, "no surface named " + quote(name) + "; expected the name of a scene surface (/surfaces, earlier "
                                                      "in the list for an offset)");
  return it->second;
}

/// The xyz of a surface (coordinates 0..2).
Surface xyz_of(const Surface& s) {
  if (s.dim() == 3) return s;
  std::vector<double> pts;
  for (int row = 0; row < s.size(); ++row)
    for (std::size_t c = 0; c < 3; ++c) pts.push_back(s.point(row)[c]);
  return Surface(s.knot_vectors(), 3, std::move(pts), s.weights());
}

}  // namespace

bool is_derived_surface(const json& item) { return item.is_object() && (item.contains("gismo") || item.contains("offset")); }

SceneSurfaceRecipe read_derived_surface(const Source& src, const json& item, const std::string& ptr, std::string name) {
  SceneSurfaceRecipe r;
  r.name = std::move(name);
  r.pointer = ptr;
  int kinds = 0;
  for (const char* k : {"surface", "gismo", "offset"}) kinds += item.contains(k) ? 1 : 0;
  if (kinds != 1)
    src.fail(ptr, std::to_string(kinds) + " of \"surface\", \"gismo\" and \"offset\"; expected exactly one (a spline, "
                                          "G+Smo patches, or an offset)");
  if (item.contains("gismo"))
    load_gismo(src, item, ptr, r);
  else
    read_offset(src, item, ptr, r);
  return r;
}

bool is_constructor(const std::string& op) {
  return std::any_of(std::begin(constructor_ops), std::end(constructor_ops), [&](const char* c) { return op == c; });
}

void read_constructor(const Source& src, const json& item, const std::string& ip, SceneOperation& o, std::size_t m) {
  SceneConstructor& c = o.constructor;
  const std::string what = "a constructor {\"op\": " + quote(o.op) + ", \"surfaces\": [NAME, ...], \"name\", \"field\", ...}";
  const std::string np = child(ip, "name");
  o.name = read_string(src, require(src, item, ip, "name", what), np, "a non-empty result name");
  if (o.name.empty()) src.fail(np, "empty name; expected a non-empty result name");
  const bool tube = o.op == "boolean_sum" && item.contains("tube");
  if (tube) {
    if (item.contains("surfaces"))
      src.fail(child(ip, "tube"), "both \"tube\" and \"surfaces\"; expected one: six faces, or a tube");
    c.tube = read_string(src, item["tube"], child(ip, "tube"), "the name of a scene surface closed in u");
    if (const json* k = find(item, "core")) {
      c.core = read_number(src, *k, child(ip, "core"));
      if (!(c.core > 0.0 && c.core < 1.0))
        src.fail(child(ip, "core"), "core " + format_double(c.core) + "; expected a relative size in (0, 1)");
    }
  } else {
    const std::string sp = child(ip, "surfaces");
    std::string count;
    std::size_t lo = 0, hi = 0;
    if (o.op == "ruled") lo = hi = 2, count = "2 surfaces [bottom, top]";
    if (o.op == "boolean_sum") lo = hi = 6, count = "6 surfaces [u0, u1, v0, v1, w0, w1] (or \"tube\": NAME)";
    if (o.op == "half_boolean_sum") lo = 2, hi = 3, count = "2 or 3 surfaces";
    if (o.op == "extrude" || o.op == "revolve") lo = hi = 1, count = "1 surface";
    if (o.op == "sweep") lo = 2, hi = 1 << 20, count = "2 or more sections";
    const json& s = require(src, item, ip, "surfaces", what);
    if (!s.is_array()) fail_type(src, sp, s, "an array of " + count);
    if (s.size() < lo || s.size() > hi)
      src.fail(sp, plural(static_cast<std::int64_t>(s.size()), "surface") + "; expected " + count);
    for (std::size_t i = 0; i < s.size(); ++i) {
      c.surfaces.push_back(read_string(src, s[i], child(sp, i), "a scene surface name"));
      if (c.surfaces.back().empty()) src.fail(child(sp, i), "empty name; expected a scene surface name");
    }
  }
  if (const json* f = find(item, "field")) {
    const std::string fp = child(ip, "field");
    c.field = read_field(src, *f, fp, m);
    try {
      construct::check_field(*c.field, static_cast<int>(m));
    } catch (const Error& e) {
      throw e.within(src.at(fp));
    }
  }
  if (const json* t = find(item, "ruling_order")) {
    if (o.op != "ruled") src.fail(child(ip, "ruling_order"), "\"ruling_order\" on " + quote(o.op) + "; expected it on \"ruled\" only");
    c.ruling_order = read_int(src, *t, child(ip, "ruling_order"), 2, 10, "an order (degree + 1) in 2..10");
  }
  if (o.op == "extrude") {
    const std::string vp = child(ip, "vector");
    const json& v = require(src, item, ip, "vector", "an extrusion {\"surfaces\": [NAME], \"vector\": [x, y, z]}");
    if (!v.is_array() || v.size() != 3) fail_type(src, vp, v, "a vector [x, y, z]");
    c.vector = read_numbers(src, v, vp, "a vector [x, y, z]");
    if (c.vector[0] == 0.0 && c.vector[1] == 0.0 && c.vector[2] == 0.0)
      src.fail(vp, "the zero vector; expected a non-zero extrusion vector");
  }
  if (o.op == "revolve") {
    // The keys of `trivox construct`'s revolve (docs/cli.md): axis, origin, angle in degrees,
    // tolerance relative to the largest distance from the axis.
    const std::string what_r = "a revolution {\"surfaces\": [NAME], \"axis\": [x, y, z], \"origin\", \"angle\", \"tolerance\"}";
    auto vec3 = [&](const char* key, const std::string& expected) {
      const std::string vp = child(ip, key);
      const json& v = require(src, item, ip, key, what_r);
      if (!v.is_array() || v.size() != 3) fail_type(src, vp, v, expected);
      const auto x = read_numbers(src, v, vp, expected);
      return std::array<double, 3>{x[0], x[1], x[2]};
    };
    c.revolution.axis = vec3("axis", "the axis direction [x, y, z]");
    if (c.revolution.axis == std::array<double, 3>{0.0, 0.0, 0.0})
      src.fail(child(ip, "axis"), "the zero vector; expected a non-zero axis direction");
    if (item.contains("origin")) c.revolution.origin = vec3("origin", "a point on the axis [x, y, z]");
    if (const json* a = find(item, "angle")) {
      const double deg = read_number(src, *a, child(ip, "angle"));
      if (!(deg > 0.0 && deg <= 360.0))
        src.fail(child(ip, "angle"), "angle " + format_double(deg) + "; expected degrees in (0, 360]");
      c.revolution.angle = deg == 360.0 ? 2.0 * std::numbers::pi : deg * std::numbers::pi / 180.0;
    }
    if (const json* t = find(item, "tolerance")) {
      c.revolution.relative_tolerance = read_number(src, *t, child(ip, "tolerance"));
      if (!(c.revolution.relative_tolerance >= 1e-12))
        src.fail(child(ip, "tolerance"), "tolerance " + format_double(c.revolution.relative_tolerance) +
                                             "; expected a relative tolerance >= 1e-12");
    }
  }
  if (o.op == "sweep") {
    if (const json* p = find(item, "params")) {
      const std::string pp = child(ip, "params");
      c.params = read_numbers(src, *p, pp, "one parameter per section, strictly increasing");
      if (c.params.size() != c.surfaces.size())
        src.fail(pp, plural(static_cast<std::int64_t>(c.params.size()), "parameter") + "; expected " +
                         std::to_string(c.surfaces.size()) + " (one per section)");
      for (std::size_t i = 1; i < c.params.size(); ++i)
        if (!(c.params[i] > c.params[i - 1]))
          src.fail(child(pp, i), format_double(c.params[i]) + " after " + format_double(c.params[i - 1]) +
                                     "; expected strictly increasing parameters");
    }
    if (const json* t = find(item, "order")) c.order = read_int(src, *t, child(ip, "order"), 2, 10, "an order in 2..10");
  }
  if (const json* t = find(item, "tolerance"); t && o.op != "revolve") {
    c.tolerance = read_number(src, *t, child(ip, "tolerance"));
    if (!(c.tolerance > 0.0)) src.fail(child(ip, "tolerance"), "tolerance " + format_double(c.tolerance) + "; expected > 0");
  }
}

std::map<std::string, Surface> resolve_surfaces(const Scene& scene, const Source& src, SceneBuild& out) {
  std::map<std::string, Surface> all;
  for (const auto& s : scene.surfaces) all.emplace(s.name, s.surface);
  for (const SceneSurfaceRecipe& r : scene.derived_surfaces) {
    const auto start = std::chrono::steady_clock::now();
    SurfaceBuild rep;
    rep.name = r.name;
    Surface s;
    if (r.merged) {
      rep.kind = "gismo";
      rep.max_gap = r.max_gap;
      s = *r.merged;
    } else {
      rep.kind = "offset";
      rep.distance = r.distance;
      const Surface& base = surface_named(src, all, r.of, r.pointer + "/offset/surface");
      try {
        s = construct::offset_surface(base, r.distance, r.offset, &rep.offset);
      } catch (const Error& e) {
        throw e.within(src.at(r.pointer + "/offset"));
      }
    }
    rep.orders = s.orders();
    rep.counts = s.counts();
    rep.seconds = seconds_since(start);
    out.surfaces.push_back(std::move(rep));
    all.emplace(r.name, std::move(s));
  }
  return all;
}

std::vector<vmodel::VCell> apply_constructor(const Scene& scene, const Source& src, const SceneOperation& op,
                                             const std::map<std::string, Surface>& surfaces, SceneBuild& out) {
  const auto start = std::chrono::steady_clock::now();
  const SceneConstructor& c = op.constructor;
  const std::size_t m = scene.properties.size();
  std::vector<Surface> in;
  std::vector<std::string> ptrs;
  if (!c.tube.empty()) {
    in.push_back(surface_named(src, surfaces, c.tube, op.pointer + "/tube"));
    ptrs.push_back(op.pointer + "/tube");
  }
  for (std::size_t i = 0; i < c.surfaces.size(); ++i) {
    ptrs.push_back(op.pointer + "/surfaces/" + std::to_string(i));
    in.push_back(surface_named(src, surfaces, c.surfaces[i], ptrs.back()));
  }
  // With a field the cells are built from xyz and coloured after; without one every input must
  // carry the scene's properties, which then ride along (construct/constructors.hpp).
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (c.field) {
      in[i] = xyz_of(in[i]);
    } else if (m > 0 && in[i].dim() != 3 + static_cast<int>(m)) {
      src.fail(op.pointer, "missing \"field\" (" + quote(i < c.surfaces.size() && c.tube.empty() ? c.surfaces[i] : c.tube) +
                               " carries no properties); expected a property field giving the " +
                               plural(static_cast<std::int64_t>(m), "property") + " of /properties");
    }
  }
  const construct::MatchOptions match{.tolerance = c.tolerance, .geometry_coords = 3};
  std::vector<construct::PrimitiveCell> cells;
  try {
    if (op.op == "ruled") {
      cells.push_back({op.name, construct::ruled(in[0], in[1], c.ruling_order)});
    } else if (op.op == "boolean_sum" && !c.tube.empty()) {
      for (auto& t : construct::tube_solid(in[0], c.core, c.tolerance))
        cells.push_back({op.name + "." + t.part, std::move(t.volume)});
    } else if (op.op == "boolean_sum") {
      cells.push_back({op.name, construct::boolean_sum(in, match)});
    } else if (op.op == "half_boolean_sum") {
      cells.push_back({op.name, in.size() == 2 ? construct::half_boolean_sum(in[0], in[1], match)
                                               : construct::half_boolean_sum(in[0], in[1], in[2], match)});
    } else if (op.op == "extrude") {
      cells.push_back({op.name, construct::extrude(in[0], c.vector)});
    } else if (op.op == "revolve") {
      cells.push_back({op.name, construct::revolve(in[0], c.revolution)});  // Massarwi & Elber 2016, Sec. 3.2.2 item 3
    } else {
      cells.push_back({op.name, construct::sweep(in, c.params, c.order)});
    }
  } catch (const Error& e) {
    throw e.within(src.at(op.pointer));
  }
  ConstructBuild rep;
  rep.name = op.name;
  rep.op = op.op;
  rep.pointer = op.pointer;
  if (c.field) {
    rep.has_field = true;
    try {
      rep.field = construct::apply_field(cells, *c.field);
    } catch (const Error& e) {
      throw e.within(src.at(op.pointer + "/field"));
    }
  }
  std::vector<vmodel::VCell> result;
  for (auto& cell : cells) {
    rep.cells.push_back(cell.name);
    result.emplace_back(std::move(cell.name), std::move(cell.volume));
  }
  rep.seconds = seconds_since(start);
  out.constructs.push_back(std::move(rep));
  return result;
}

}  // namespace trivox::scene::detail
