// Input limits (trivox/limits.hpp, docs/limits.md): parsing NAME=N, each limit refused by the
// JSON and G+Smo readers with the place and the limit's name, the streaming pass of JSON models
// (every model of the repository followed to its end; a wrong count refused with the reader's
// message), the file size checked before reading, and the orders checked by quadrature and
// validity before anything is built.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "io_test_util.hpp"
#include "../../src/io/model_scan.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/geom/validity.hpp"
#include "trivox/io/gismo_xml.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/io/model_json.hpp"
#include "trivox/limits.hpp"
#include "trivox/spline/knot_vector.hpp"
#include "trivox/spline/tensor_spline.hpp"

namespace {

using nlohmann::json;
using trivox::Limits;
using trivox::io::test::check_message;
using trivox::io::test::error_of;

/// One cell of order `p` along u (p control points evenly spaced: x = u), order 2 along v, w.
json line_cell(int p, const std::string& name = "c") {
  json ku = json::array();
  for (int i = 0; i < p; ++i) ku.push_back(0.0);
  for (int i = 0; i < p; ++i) ku.push_back(1.0);
  json points = json::array();
  for (int w = 0; w < 2; ++w)
    for (int v = 0; v < 2; ++v)
      for (int u = 0; u < p; ++u) points.push_back({p > 1 ? double(u) / (p - 1) : 0.0, v, w});
  return {{"name", name},
          {"trivariate", {{"orders", {p, 2, 2}}, {"knots", {ku, {0, 0, 1, 1}, {0, 0, 1, 1}}}, {"points", points}}}};
}

/// A model of the given cells. A vector, not a json parameter: a braced list of one json object
/// initialises a json as a copy of that object with clang and as a one-element array with gcc.
json model(const std::vector<json>& cells, json properties = json::array()) {
  return {{"trivox", 1}, {"units", "mm"}, {"properties", properties}, {"cells", cells}};
}

std::string read_error(const json& j, const Limits& limits) {
  return error_of([&] { trivox::io::read_model_json(j.dump(), "m.json", limits); });
}

/// Restores the process's default limits at scope exit.
struct DefaultLimits {
  Limits saved = trivox::default_limits();
  ~DefaultLimits() { trivox::set_default_limits(saved); }
};

}  // namespace

TEST_CASE("limits: NAME=N assignments, and refusals naming the text and the names") {
  Limits l;
  CHECK(l.max_order == 32);
  CHECK(l.max_file_bytes == std::int64_t{1} << 30);
  trivox::set_limit(l, "max_order=64", "--limit");
  CHECK(l.max_order == 64);
  trivox::set_limits(l, "max_points=2.5e6,max_file_bytes=4e9,", "TRIVOX_LIMITS");
  CHECK(l.max_points == 2500000);
  CHECK(l.max_file_bytes == 4000000000);
  check_message(error_of([&] { trivox::set_limit(l, "max_order", "--limit"); }), {"--limit max_order", "no '='", "max_cells"});
  check_message(error_of([&] { trivox::set_limit(l, "order=3", "--limit"); }), {"unknown limit \"order\"", "max_order"});
  for (const char* bad : {"max_order=0", "max_order=-1", "max_order=1.5", "max_order=", "max_order=1e19", "max_order=nan"})
    check_message(error_of([&] { trivox::set_limit(l, bad, "--limit"); }), {bad, "expected max_order=N"});
  CHECK(l.max_order == 64);  // refusals change nothing
  CHECK(trivox::limit_table().size() == 6);
}

TEST_CASE("limits: an order above max_order is refused by the streaming pass, before the tree") {
  const json m = model({line_cell(3, "a"), line_cell(40, "b")});
  check_message(read_error(m, Limits{}), {"m.json: /cells/1/trivariate/orders/0: 40; expected an order of at most 32",
                                          "(limit max_order; raise it with --limit max_order=N)"});
  Limits raised;
  raised.max_order = 40;
  CHECK(trivox::io::read_model_json(m.dump(), "m.json", raised).cells.size() == 2);
  // A huge order is refused without the knots it would need (20000 orders, 4 knots).
  json huge = model({line_cell(2)});
  huge["cells"][0]["trivariate"]["orders"][0] = 20000;
  check_message(read_error(huge, Limits{}), {"/cells/0/trivariate/orders/0: 20000; expected an order of at most 32"});
}

TEST_CASE("limits: control points, knots, cells, properties and names") {
  Limits l;
  l.max_points = 15;  // line_cell(4) has 4 x 2 x 2 = 16
  check_message(read_error(model({line_cell(3), line_cell(4, "d")}), l),
                {"/cells/1/trivariate/knots: 4 x 2 x 2 control points (from the knot vectors and orders); expected at most 15",
                 "(limit max_points;"});
  // Points before knots: the array's own length is the first thing over the limit.
  json early = model({line_cell(4)});
  json tri = {{"points", early["cells"][0]["trivariate"]["points"]}, {"orders", {4, 2, 2}}};
  early["cells"][0]["trivariate"] = tri;
  check_message(read_error(early, l), {"/cells/0/trivariate/points: more than 15 control points; expected at most 15", "max_points"});

  Limits c;
  c.max_cells = 2;
  check_message(read_error(model({line_cell(2, "a"), line_cell(2, "b"), line_cell(2, "x")}), c),
                {"/cells/2: more than 2 cells and surfaces; expected at most 2", "(limit max_cells;"});
  CHECK(trivox::io::read_model_json(model({line_cell(2, "a"), line_cell(2, "b")}).dump(), "m.json", c).cells.size() == 2);

  Limits p;
  p.max_properties = 2;
  json three = model({line_cell(2)}, {"r", "g", "b"});
  check_message(read_error(three, p), {"/properties: more than 2 properties; expected at most 2", "(limit max_properties;"});

  const std::string long_name(300, 'n');
  check_message(read_error(model({line_cell(2, long_name)}), Limits{}),
                {"/cells/0/name: a name of 300 bytes; expected at most 256 bytes", "(limit max_name_bytes;"});
  check_message(read_error(model({line_cell(2)}, {long_name}), Limits{}), {"/properties/0: a name of 300 bytes"});
  // Escapes count as the bytes they stand for: 200 "\u00e9" are 400 bytes of UTF-8, 1200 of text.
  std::string escaped;
  for (int i = 0; i < 200; ++i) escaped += "\\u00e9";
  const std::string text = R"({"trivox": 1, "cells": [{"name": ")" + escaped + R"(", "trivariate": )" +
                           line_cell(2)["trivariate"].dump() + "}]}";
  check_message(error_of([&] { trivox::io::read_model_json(text, "e.json", Limits{}); }), {"a name of 400 bytes"});
  Limits wide;
  wide.max_name_bytes = 400;
  CHECK(trivox::io::read_model_json(text, "e.json", wide).cells[0].name.size() == 400);
}

TEST_CASE("limits: a wrong count of control points is refused by the streaming pass with the reader's message") {
  json m = model({line_cell(3, "a"), line_cell(5, "b")});
  m["cells"][1]["trivariate"]["points"].erase(0);
  const std::string scanned = error_of([&] { trivox::io::scan_model_json(m.dump(), "m.json", Limits{}); });
  CHECK(scanned == "m.json: /cells/1/trivariate/points: 19 control points; expected 20 (5 x 2 x 2, from the knot vectors and orders)");
  CHECK(read_error(m, Limits{}) == scanned);
  // Malformed knots or orders are the reader's to report: the pass says nothing about them.
  json bad = model({line_cell(3)});
  bad["cells"][0]["trivariate"]["knots"][0][1] = -1.0;  // decreasing
  bad["cells"][0]["trivariate"]["points"].erase(0);
  CHECK(trivox::io::scan_model_json(bad.dump(), "m.json", Limits{}));
  check_message(read_error(bad, Limits{}), {"/cells/0/trivariate/knots/0/1", "non-decreasing"});
}

TEST_CASE("limits: the streaming pass follows every model and scene of the repository to its end") {
  namespace fs = std::filesystem;
  int files = 0;
  for (const fs::path& dir : {trivox::io::test::source_dir() / "models", trivox::io::test::source_dir() / "tests" / "data"})
    for (const auto& e : fs::directory_iterator(dir))
      if (e.path().extension() == ".json") {
        INFO(e.path());
        CHECK(trivox::io::scan_model_json(trivox::io::test::slurp(e.path()), e.path().string(), Limits{}));
        ++files;
      }
  CHECK(files >= 10);
  // A byte-order mark is skipped as the parser skips it; malformed text stops the pass.
  CHECK(trivox::io::scan_model_json("\xEF\xBB\xBF" + model({line_cell(2)}).dump(), "b.json", Limits{}));
  CHECK_FALSE(trivox::io::scan_model_json("{\"trivox\": 1, \"cells\": [", "t.json", Limits{}));
}

TEST_CASE("limits: G+Smo degrees, counts, geoDim and geometries") {
  const auto patch = [](int degree, int n, int geo_dim) {
    std::string knots;
    for (int i = 0; i <= degree; ++i) knots += "0 ";
    for (int i = 0; i < n - degree - 1; ++i) knots += "0.5 ";
    for (int i = 0; i <= degree; ++i) knots += "1 ";
    std::string coefs;
    for (int i = 0; i < n * 4 * geo_dim; ++i) coefs += "0 ";
    return "<Geometry type=\"TensorBSpline3\"><Basis type=\"TensorBSplineBasis3\">"
           "<Basis type=\"BSplineBasis\" index=\"0\"><KnotVector degree=\"" + std::to_string(degree) + "\">" + knots +
           "</KnotVector></Basis><Basis type=\"BSplineBasis\" index=\"1\"><KnotVector degree=\"1\">0 0 1 1</KnotVector></Basis>"
           "<Basis type=\"BSplineBasis\" index=\"2\"><KnotVector degree=\"1\">0 0 1 1</KnotVector></Basis></Basis>"
           "<coefs geoDim=\"" + std::to_string(geo_dim) + "\">" + coefs + "</coefs></Geometry>";
  };
  const auto xml = [](const std::string& body) { return "<xml>" + body + "</xml>"; };
  CHECK(trivox::io::read_gismo_xml(xml(patch(2, 3, 3)), "g.xml", Limits{}).cells.size() == 1);
  check_message(error_of([&] { trivox::io::read_gismo_xml(xml(patch(40, 41, 3)), "g.xml", Limits{}); }),
                {"g.xml: Geometry[0]", "KnotVector", "degree=\"40\"; expected a degree of at most 31 (an order of at most 32)",
                 "(limit max_order;"});
  Limits l;
  l.max_points = 11;
  check_message(error_of([&] { trivox::io::read_gismo_xml(xml(patch(1, 3, 3)), "g.xml", l); }),
                {"3 x 2 x 2 control points (from the knot vectors); expected at most 11 per patch", "(limit max_points;"});
  l = Limits{};
  l.max_properties = 1;
  check_message(error_of([&] { trivox::io::read_gismo_xml(xml(patch(1, 2, 5)), "g.xml", l); }),
                {"geoDim=\"5\" (2 properties); expected at most 1 properties", "(limit max_properties;"});
  l = Limits{};
  l.max_cells = 1;
  check_message(error_of([&] { trivox::io::read_gismo_xml(xml(patch(1, 2, 3) + patch(1, 2, 3)), "g.xml", l); }),
                {"g.xml: Geometry[1]", "more than 1 geometries", "(limit max_cells;"});
}

TEST_CASE("limits: the file size is checked before reading, and a device is read only up to the limit") {
  trivox::io::test::TempDir dir("limits");
  const auto file = dir.path() / "m.json";
  const std::string text = model({line_cell(2)}).dump();
  {
    std::ofstream out(file, std::ios::binary);
    out << text;
  }
  Limits l;
  l.max_file_bytes = static_cast<std::int64_t>(text.size());
  CHECK(trivox::io::load_model(file, l).cells.size() == 1);
  l.max_file_bytes = static_cast<std::int64_t>(text.size()) - 1;
  check_message(error_of([&] { trivox::io::load_model(file, l); }),
                {file.string() + ": file size: " + std::to_string(text.size()) + " bytes; expected at most " +
                     std::to_string(text.size() - 1) + " bytes (limit max_file_bytes; raise it with --limit max_file_bytes=N)"});
  // /dev/zero never ends: read up to the limit, then refused.
  l.max_file_bytes = 1 << 20;
  check_message(error_of([&] { trivox::io::load_model("/dev/zero", l); }),
                {"/dev/zero: file size: more than 1048576 bytes", "max_file_bytes"});
}

TEST_CASE("limits: quadrature and validity check the orders against the default limits before building") {
  DefaultLimits restore;
  using trivox::spline::KnotVector;
  const int p = 40;
  const trivox::spline::Trivariate cell(
      {KnotVector::bezier(p), KnotVector::bezier(2), KnotVector::bezier(2)}, 3, [&] {
        std::vector<double> pts;
        for (int w = 0; w < 2; ++w)
          for (int v = 0; v < 2; ++v)
            for (int u = 0; u < p; ++u) pts.insert(pts.end(), {double(u) / (p - 1), double(v), double(w)});
        return pts;
      }());
  check_message(error_of([&] { trivox::geom::signed_volume(cell); }),
                {"integral over a cell, direction u: order 40; expected an order of at most 32", "(limit max_order;"});
  check_message(error_of([&] { trivox::geom::check_validity(cell); }),
                {"validity of a cell, direction u: order 40; expected an order of at most 32"});
  Limits raised;
  raised.max_order = 40;
  trivox::set_default_limits(raised);
  // x = u, y = v, z = w: volume 1, exactly (60 Gauss points per direction along u).
  CHECK(trivox::geom::signed_volume(cell) == Approx(1.0).epsilon(1e-13));
}
