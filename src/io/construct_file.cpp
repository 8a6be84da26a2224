#include "trivox/io/construct_file.hpp"

#include <algorithm>
#include <cmath>

#include "json_io.hpp"
#include "trivox/error.hpp"
#include "trivox/io/model_json.hpp"

namespace trivox::io {

namespace {

using namespace json_io;

constexpr double pi = 3.14159265358979323846;

std::string known_ops() {
  std::string s;
  for (const char* op : construct_ops) s += (s.empty() ? "" : ", ") + std::string(op);
  return s;
}

/// How many inputs each op takes, and which: "4 curves or 6 surfaces".
struct Arity {
  std::vector<int> curves, surfaces;
};

Arity arity(const std::string& op) {
  if (op == "boolean_sum") return {{4}, {6}};
  if (op == "half_boolean_sum") return {{2}, {2, 3}};
  if (op == "ruled") return {{2}, {2}};
  if (op == "extrude" || op == "revolve") return {{1}, {1}};
  return {{-1}, {-1}};  // sweep: 2 or more
}

std::string arity_text(const std::vector<int>& counts, const char* kind) {
  if (counts[0] < 0) return std::string("2 or more ") + kind;
  std::string s;
  for (std::size_t i = 0; i < counts.size(); ++i) s += (i ? " or " : "") + std::to_string(counts[i]);
  return s + " " + kind;
}

template <int P>
std::vector<spline::TensorSpline<P>> read_inputs(const Source& src, const json& list, const std::string& ptr,
                                                 const std::vector<int>& counts, const std::string& op, int& dim) {
  const char* kind = P == 1 ? "curves" : "surfaces";
  expect_array(src, list, ptr, std::string("an array of ") + kind);
  const auto n = static_cast<int>(list.size());
  const bool ok = counts[0] < 0 ? n >= 2 : std::find(counts.begin(), counts.end(), n) != counts.end();
  if (!ok)
    src.fail(ptr, plural(n, P == 1 ? "curve" : "surface") + " for \"" + op + "\"; expected " + arity_text(counts, kind));
  std::vector<spline::TensorSpline<P>> out;
  for (int i = 0; i < n; ++i) {
    const std::string p = child(ptr, static_cast<std::size_t>(i));
    const json& item = list[static_cast<std::size_t>(i)];
    if (i == 0) {
      // The first control point fixes the coordinate count for every input.
      const json* pts = item.is_object() ? find(item, "points") : nullptr;
      if (pts && pts->is_array() && !pts->empty() && (*pts)[0].is_array()) {
        const auto k = (*pts)[0].size();
        if (k < 1 || k > 64)
          src.fail(child(child(p, "points"), std::size_t{0}), plural(static_cast<std::int64_t>(k), "coordinate") +
                                                     "; expected 1..64 (xy or xyz, then properties)");
        dim = static_cast<int>(k);
      } else {
        dim = 2;  // read_spline reports what is wrong with "points"
      }
    }
    const PointShape shape{dim, std::to_string(dim) + (i == 0 ? "" : " (as in " + child(ptr, std::size_t{0}) + ")")};
    out.push_back(read_spline<P>(src, item, p, shape));
  }
  return out;
}

std::vector<double> read_vector(const Source& src, const json& root, const char* key, std::size_t lo, std::size_t hi,
                                const std::string& expected) {
  const std::string ptr = child(std::string(), key);
  const std::vector<double> v = read_numbers(src, require(src, root, "", key, expected), ptr, expected);
  if (v.size() < lo || v.size() > hi) src.fail(ptr, plural(static_cast<std::int64_t>(v.size()), "value") + "; expected " + expected);
  return v;
}

double read_optional_number(const Source& src, const json& root, const char* key, double fallback) {
  const json* j = find(root, key);
  return j ? read_number(src, *j, child(std::string(), key)) : fallback;
}

template <int P>
std::string write_one(const spline::TensorSpline<P>& s, const char* list) {
  std::string out = "{\n  \"trivox\": 1,\n  \"" + std::string(list) + "\": [\n    ";
  write_spline(out, s, "    ");
  out += "\n  ]\n}\n";
  return out;
}

}  // namespace

ConstructInput read_construct_input(std::string_view text, const std::string& source) {
  const Source src{source};
  const json root = parse(src, text);
  const std::string what = "a constructor input {\"trivox\": 1, \"op\", \"curves\" or \"surfaces\", ...}";
  expect_object(src, root, "", what);
  const json& v = require(src, root, "", "trivox", "\"trivox\": 1 (the format version)");
  if (!v.is_number() || v != model_format_version) fail_type(src, "/trivox", v, "the format version 1");
  ConstructInput in;
  in.op = read_string(src, require(src, root, "", "op", what), "/op", "the name of a constructor (" + known_ops() + ")");
  if (std::find_if(std::begin(construct_ops), std::end(construct_ops), [&](const char* o) { return in.op == o; }) ==
      std::end(construct_ops))
    src.fail("/op", "unknown constructor \"" + in.op + "\"; expected one of " + known_ops());
  const json* curves = find(root, "curves");
  const json* surfaces = find(root, "surfaces");
  if ((curves != nullptr) == (surfaces != nullptr))
    src.fail("", curves ? "both \"curves\" and \"surfaces\"; expected one of them"
                        : "missing \"curves\" (to make a surface) or \"surfaces\" (to make a trivariate)");
  const Arity a = arity(in.op);
  if (curves) in.curves = read_inputs<1>(src, *curves, "/curves", a.curves, in.op, in.dim);
  else in.surfaces = read_inputs<2>(src, *surfaces, "/surfaces", a.surfaces, in.op, in.dim);

  in.match.tolerance = read_optional_number(src, root, "tolerance", in.match.tolerance);
  if (!(in.match.tolerance >= 0)) src.fail("/tolerance", "tolerance " + format_double(in.match.tolerance) + "; expected a value >= 0");
  if (const json* j = find(root, "ruling_order"))
    in.ruling_order = read_int(src, *j, "/ruling_order", 2, 16, "an integer ruling order in 2..16");
  if (in.op == "extrude")
    in.vector = read_vector(src, root, "vector", 1, static_cast<std::size_t>(in.dim),
                            "the extrusion vector: 1.." + std::to_string(in.dim) + " numbers");
  if (in.op == "revolve") {
    if (in.dim < 3) src.fail(curves ? "/curves/0/points/0" : "/surfaces/0/points/0",
                             plural(in.dim, "coordinate") + "; expected at least 3 (xyz) for a revolution");
    const auto axis = read_vector(src, root, "axis", 3, 3, "the axis direction [x, y, z]");
    in.revolution.axis = {axis[0], axis[1], axis[2]};
    if (find(root, "origin")) {
      const auto o = read_vector(src, root, "origin", 3, 3, "a point on the axis [x, y, z]");
      in.revolution.origin = {o[0], o[1], o[2]};
    }
    const double deg = read_optional_number(src, root, "angle", 360.0);
    if (!(deg > 0 && deg <= 360)) src.fail("/angle", "angle " + format_double(deg) + "; expected degrees in (0, 360]");
    in.revolution.angle = deg == 360.0 ? 2 * pi : deg * pi / 180.0;
    in.revolution.relative_tolerance = read_optional_number(src, root, "tolerance", 1e-6);
    if (!(in.revolution.relative_tolerance >= 1e-12))
      src.fail("/tolerance", "tolerance " + format_double(in.revolution.relative_tolerance) +
                                 "; expected a relative tolerance >= 1e-12");
    in.match.tolerance = 1e-9;
  }
  if (in.op == "sweep") {
    if (find(root, "params")) {
      const std::size_t n = curves ? in.curves.size() : in.surfaces.size();
      in.params = read_vector(src, root, "params", n, n, "one parameter per section (" + std::to_string(n) + ")");
    }
    if (const json* j = find(root, "order")) in.order = read_int(src, *j, "/order", 1, 16, "an integer order in 1..16");
  }
  return in;
}

std::string write_construct_output(const spline::Surface& s) { return write_one(s, "surfaces"); }
std::string write_construct_output(const spline::Trivariate& t) { return write_one(t, "trivariates"); }

}  // namespace trivox::io
