// G+Smo XML import: the reference files in models/gismo (expected values read off the file
// text), rational and higher-dimensional geometry, and one test per kind of malformed input.
#include <random>

#include "io_test_util.hpp"
#include "trivox/io/gismo_xml.hpp"

namespace {

using trivox::io::read_gismo_xml;
using trivox::io::test::check_message;
using trivox::io::test::error_of;
using trivox::io::test::slurp;
using trivox::io::test::source_dir;
using namespace trivox::spline;
using trivox::vmodel::VModel;

VModel load_fixture(const std::string& name) {
  const auto path = source_dir() / "models" / "gismo" / name;
  return read_gismo_xml(slurp(path), name);
}

template <class Spline>
std::vector<double> point(const Spline& s, int row) {
  const auto p = s.point(row);
  return {p.begin(), p.end()};
}

using V = std::vector<double>;

/// One `<Basis type="BSplineBasis">` per direction, as G+Smo writes them.
std::string bspline_basis(int params, const std::string& knots, int degree) {
  std::string s = "<Basis type=\"TensorBSplineBasis" + std::to_string(params) + "\">\n";
  for (int d = 0; d < params; ++d)
    s += " <Basis type=\"BSplineBasis\" index=\"" + std::to_string(d) + "\"><KnotVector degree=\"" +
         std::to_string(degree) + "\">" + knots + "</KnotVector></Basis>\n";
  return s + "</Basis>\n";
}

/// A trilinear unit cube (8 control points, u fastest) as a TensorBSpline3 element.
std::string unit_cube(const std::string& id = "0", const std::string& coefs_attr = "geoDim=\"3\"") {
  return "<Geometry type=\"TensorBSpline3\" id=\"" + id + "\">\n" + bspline_basis(3, "0 0 1 1", 1) +
         "<coefs " + coefs_attr + ">0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1</coefs>\n"
         "</Geometry>\n";
}

std::string xml(const std::string& body) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<xml>\n" + body + "</xml>\n";
}

std::string error_for(const std::string& text) {
  return error_of([&] { read_gismo_xml(text, "bad.xml"); });
}

}  // namespace

// --------------------------------------------------------------------------------------------
// The reference files

TEST_CASE("cube.xml: seven trilinear patches", "[io][gismo]") {
  const VModel m = load_fixture("cube.xml");
  CHECK(m.units == "mm");
  CHECK(m.properties.empty());
  CHECK(m.surfaces.empty());
  REQUIRE(m.cells.size() == 7);
  for (std::size_t i = 0; i < m.cells.size(); ++i) {
    CHECK(m.cells[i].name == "patch" + std::to_string(i));  // ids are all "1": names use order
    CHECK(m.cells[i].volume.orders() == Trivariate::Index{2, 2, 2});
    CHECK(m.cells[i].volume.counts() == Trivariate::Index{2, 2, 2});
    CHECK(m.cells[i].volume.dim() == 3);
    CHECK_FALSE(m.cells[i].volume.rational());
  }
  CHECK(m.cells[0].volume.knots(0).knots() == V{0, 0, 1, 1});
  CHECK(point(m.cells[0].volume, 0) == V{0, 0, 0});
  CHECK(point(m.cells[0].volume, 7) == V{1, 1, 1});
  CHECK(point(m.cells[1].volume, 4) == V{-1, -1, -1});  // the frustum below the middle cube
  CHECK(point(m.cells[6].volume, 0) == V{2, -1, -1});
  CHECK(point(m.cells[6].volume, 7) == V{1, 1, 1});
}

TEST_CASE("fichera.xml: a comment before the declaration, a MultiPatch to ignore", "[io][gismo]") {
  const VModel m = load_fixture("fichera.xml");
  REQUIRE(m.cells.size() == 7);
  CHECK(m.surfaces.empty());
  CHECK(point(m.cells[0].volume, 0) == V{0, -1, 0});
  CHECK(point(m.cells[0].volume, 1) == V{1, -1, 0});
  CHECK(point(m.cells[0].volume, 7) == V{1, 0, 1});
  CHECK(point(m.cells[6].volume, 0) == V{-1, -1, 0});
}

TEST_CASE("teapot.xml: thirty-two bicubic surfaces", "[io][gismo]") {
  const VModel m = load_fixture("teapot.xml");
  CHECK(m.cells.empty());
  REQUIRE(m.surfaces.size() == 32);
  for (const auto& s : m.surfaces) {
    CHECK(s.surface.orders() == Surface::Index{4, 4});
    CHECK(s.surface.size() == 16);
  }
  CHECK(m.surfaces[0].name == "patch0");
  CHECK(m.surfaces[31].name == "patch31");
  CHECK(point(m.surfaces[0].surface, 0) == V{1.4, 0.0, 2.4});
  CHECK(point(m.surfaces[0].surface, 1) == V{1.4, -0.784, 2.4});
  CHECK(point(m.surfaces[0].surface, 15) == V{0.0, -1.5, 2.4});
  CHECK(point(m.surfaces[1].surface, 1) == V{-0.784, -1.4, 2.4});
  CHECK(point(m.surfaces[31].surface, 0) == V{0, 0, 0});
  CHECK(point(m.surfaces[31].surface, 5) == V{0.798, -1.425, 0.0});
  CHECK(point(m.surfaces[31].surface, 15) == V{1.5, 0.0, 0.15});
}

// --------------------------------------------------------------------------------------------
// Other valid input

TEST_CASE("TensorNurbs3 and TensorNurbs2 carry their weights", "[io][gismo]") {
  const std::string text = xml(
      "<Geometry type=\"TensorNurbs3\" id=\"102\">\n<Basis type=\"TensorNurbsBasis3\">\n" +
      bspline_basis(3, "0 0 1 1", 1) + "<weights>1 0.5 1 1\n1 1 0.25 1</weights>\n</Basis>\n" +
      "<coefs geoDim=\"3\">0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1</coefs>\n"
      "</Geometry>\n"
      "<Geometry type=\"TensorNurbs2\" id=\"9\">\n<Basis type=\"TensorNurbsBasis2\">\n" +
      bspline_basis(2, "0 0 0 1 1 1", 2) +
      "<weights format=\"ASCII\">1 0.707106781186548 1 1 0.707106781186548 1 1 "
      "0.707106781186548 1</weights>\n</Basis>\n"
      "<coefs geoDim=\"3\" format=\"ASCII\">1 0 0\n1 1 0\n0 1 0\n1 0 1\n1 1 1\n0 1 1\n1 0 2\n1 1 2\n0 1 2</coefs>\n"
      "</Geometry>\n");
  const VModel m = read_gismo_xml(text, "nurbs.xml");
  REQUIRE(m.cells.size() == 1);
  REQUIRE(m.surfaces.size() == 1);
  CHECK(m.cells[0].name == "patch0");
  CHECK(m.surfaces[0].name == "patch1");  // one numbering for all geometries, in file order
  CHECK(m.cells[0].volume.weights() == V{1, 0.5, 1, 1, 1, 1, 0.25, 1});
  CHECK(m.surfaces[0].surface.orders() == Surface::Index{3, 3});
  CHECK(m.surfaces[0].surface.weights()[4] == 0.707106781186548);
  CHECK(point(m.surfaces[0].surface, 8) == V{0, 1, 2});
}

TEST_CASE("geoDim 2 is planar and geoDim above 3 adds properties", "[io][gismo]") {
  const std::string planar = xml(
      "<Geometry type=\"TensorBSpline2\" id=\"100\">\n" + bspline_basis(2, "0 0 1 1", 1) +
      "<coefs geoDim=\"2\">0 0\n2 0\n0 3\n2.5 3</coefs></Geometry>\n");
  const VModel p = read_gismo_xml(planar, "planar.xml");
  REQUIRE(p.surfaces.size() == 1);
  CHECK(p.surfaces[0].surface.dim() == 3);
  CHECK(point(p.surfaces[0].surface, 3) == V{2.5, 3, 0});

  const std::string coloured = xml(
      "<Geometry type=\"TensorBSpline3\">\n" + bspline_basis(3, "0 0 1 1", 1) +
      "<coefs geoDim=\"5\">0 0 0 1 2\n1 0 0 1 2\n0 1 0 1 2\n1 1 0 1 2\n"
      "0 0 1 3 4\n1 0 1 3 4\n0 1 1 3 4\n1 1 1 3 4</coefs></Geometry>\n");
  const VModel c = read_gismo_xml(coloured, "coloured.xml");
  CHECK(c.properties == std::vector<std::string>{"p0", "p1"});
  CHECK(point(c.cells.at(0).volume, 7) == V{1, 1, 1, 3, 4});
}

TEST_CASE("bases are placed by their index attribute", "[io][gismo]") {
  const std::string text = xml(
      "<Geometry type=\"TensorBSpline2\">\n<Basis type=\"TensorBSplineBasis2\">\n"
      "<Basis type=\"BSplineBasis\" index=\"1\"><KnotVector degree=\"2\">0 0 0 1 1 1</KnotVector></Basis>\n"
      "<Basis type=\"BSplineBasis\" index=\"0\"><KnotVector degree=\"1\">0 0 1 1</KnotVector></Basis>\n"
      "</Basis>\n<coefs geoDim=\"3\">0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 2 0\n1 2 0</coefs></Geometry>\n");
  const VModel m = read_gismo_xml(text, "order.xml");
  CHECK(m.surfaces.at(0).surface.orders() == Surface::Index{2, 3});
  CHECK(m.surfaces.at(0).surface.counts() == Surface::Index{2, 3});
}

TEST_CASE("numbers are read exactly, with signs and exponents", "[io][gismo]") {
  const std::string text = xml(
      "<Geometry type=\"TensorBSpline2\">\n" + bspline_basis(2, "0 0 1 1", 1) +
      "<coefs geoDim=\"3\">0.1 -0.0 +2.5\n1e-300 4.9e-324 1.7976931348623157e308\n"
      "-1e-400 1 0\n1 1 0</coefs></Geometry>\n");
  const VModel m = read_gismo_xml(text, "exact.xml");
  CHECK(point(m.surfaces.at(0).surface, 2) == V{0, 1, 0});  // underflow: the nearest double
  CHECK(std::signbit(m.surfaces[0].surface.point(2)[0]));
  CHECK(point(m.surfaces.at(0).surface, 0) == V{0.1, 0.0, 2.5});
  CHECK(std::signbit(m.surfaces[0].surface.point(0)[1]));
  CHECK(point(m.surfaces[0].surface, 1) == V{1e-300, 4.9e-324, 1.7976931348623157e308});
}

// --------------------------------------------------------------------------------------------
// Malformed input: one case each

TEST_CASE("malformed XML is reported with its line and column", "[io][gismo][bad]") {
  check_message(error_for("<xml>\n <Geometry type=\"TensorBSpline3\">\n </Geometri>\n</xml>"),
                {"bad.xml: line 3, column", "malformed XML", "expected well-formed XML"});
  check_message(error_for(""), {"bad.xml: line 1, column 1: malformed XML", "expected"});
  check_message(error_for("<xml><Geometry type=\"a></xml>"), {"bad.xml: line 1", "malformed XML", "expected"});
}

TEST_CASE("the root must be <xml> and hold geometry", "[io][gismo][bad]") {
  check_message(error_for("<gismo><Geometry/></gismo>"),
                {"bad.xml: gismo (line 1): root element <gismo>; expected <xml>"});
  check_message(error_for(xml("<MultiPatch parDim=\"3\" id=\"7\"/>\n")),
                {"bad.xml: xml (line 2): no <Geometry> elements; expected at least one"});
}

TEST_CASE("unknown geometry types are named", "[io][gismo][bad]") {
  const std::string curve = xml(unit_cube() +
                                "<Geometry type=\"BSpline\" id=\"3\">\n<Basis type=\"BSplineBasis\">"
                                "<KnotVector degree=\"1\">0 0 1 1</KnotVector></Basis>\n"
                                "<coefs geoDim=\"3\">0 0 0\n1 0 0</coefs></Geometry>\n");
  check_message(error_for(curve), {"bad.xml: Geometry[1] (id=\"3\") (line 18): geometry type=\"BSpline\"; expected TensorBSpline3"});
  check_message(error_for(xml("<Geometry id=\"3\"/>\n")),
                {"bad.xml: Geometry[0] (id=\"3\")", "type=\"\"; expected TensorBSpline3"});
}

TEST_CASE("missing or mistyped bases", "[io][gismo][bad]") {
  check_message(error_for(xml("<Geometry type=\"TensorBSpline3\" id=\"4\"><coefs geoDim=\"3\"/></Geometry>\n")),
                {"bad.xml: Geometry[0] (id=\"4\") (line 3): missing <Basis>; expected a <Basis type=\"TensorBSplineBasis3\">"});
  std::string t = unit_cube();
  t.replace(t.find("TensorBSplineBasis3"), 19, "TensorBSplineBasis2");
  check_message(error_for(xml(t)), {"bad.xml: Geometry[0] (id=\"0\") / Basis type=\"TensorBSplineBasis2\"",
                                    "type=\"TensorBSplineBasis2\"; expected type=\"TensorBSplineBasis3\""});
  t = unit_cube();
  t.replace(t.find("BSplineBasis\" index=\"1\""), 12, "NurbsBasis");
  check_message(error_for(xml(t)), {"/ Basis index=\"1\"", "type=\"NurbsBasis\"; expected type=\"BSplineBasis\""});
  t = unit_cube();
  t.replace(t.find("index=\"2\""), 9, "index=\"1\"");
  check_message(error_for(xml(t)), {"/ Basis index=\"1\"", "a second basis for direction 1; expected one"});
  t = unit_cube();
  t.replace(t.find("index=\"2\""), 9, "index=\"3\"");
  check_message(error_for(xml(t)), {"/ Basis index=\"3\"", "index=\"3\"; expected an index from 0 to 2"});
  t = unit_cube();
  const auto b = t.find(" <Basis type=\"BSplineBasis\" index=\"2\"");
  t.erase(b, t.find("</Basis>", b) + 9 - b);
  check_message(error_for(xml(t)), {"Basis type=\"TensorBSplineBasis3\"", "2 BSplineBasis children; expected 3"});
}

TEST_CASE("knot vectors: a degree and enough non-decreasing numbers", "[io][gismo][bad]") {
  const std::string where =
      "bad.xml: Geometry[0] (id=\"0\") / Basis type=\"TensorBSplineBasis3\" / Basis index=\"1\" / KnotVector (line 6)";
  std::string t = unit_cube();
  const auto kv1 = t.find("degree=\"1\">0 0 1 1", t.find("index=\"1\""));
  t.replace(kv1, 18, "degree=\"1\">0 0 1 0.5");
  check_message(error_for(xml(t)), {where + ": knot 3 (0.5) is less than knot 2 (1); expected non-decreasing knots"});
  t = unit_cube();
  t.replace(kv1, 18, "degree=\"1\">0 0 1");
  check_message(error_for(xml(t)), {where + ": 3 knots for order 2; expected at least 4"});
  t = unit_cube();
  t.replace(kv1, 18, "degree=\"-1\">0 0 1 1");
  check_message(error_for(xml(t)), {where + ": degree=\"-1\"; expected degree=\"p\" with 0 <= p"});
  t = unit_cube();
  t.replace(kv1, 18, "degree=\"999999999999\">0 0 1 1");
  check_message(error_for(xml(t)), {where + ": degree=\"999999999999\"; expected"});
  t = unit_cube();
  t.replace(kv1, 18, ">0 0 1 1");
  check_message(error_for(xml(t)), {where + ": missing degree attribute; expected"});
  t = unit_cube();
  t.replace(kv1, 18, "degree=\"1\">0 0 one 1");
  check_message(error_for(xml(t)), {where + ": number 2 \"one\" is not a number; expected numbers"});
  t = unit_cube();
  t.replace(kv1, 18, "degree=\"1\">0 0 nan 1");
  check_message(error_for(xml(t)), {where + ": number 2 \"nan\" is not finite; expected a finite number"});
  t = unit_cube();
  t.replace(kv1, 18, "degree=\"1\">0 0 1e999 1e999");
  check_message(error_for(xml(t)), {where + ": number 2 \"1e999\" is not finite; expected a finite number"});
  t = unit_cube();
  t.replace(kv1, 18, "degree=\"1\">1 1 1 1");
  check_message(error_for(xml(t)), {where + ": empty domain", "expected"});
  t = unit_cube();
  t.replace(kv1, 18, "degree=\"1\" format=\"B64Float64\">AAAA");
  check_message(error_for(xml(t)), {where + ": format=\"B64Float64\"; expected format=\"ASCII\""});
}

TEST_CASE("coefs: geoDim and the number of values must match the basis", "[io][gismo][bad]") {
  check_message(error_for(xml(unit_cube("0", ""))),
                {"bad.xml: Geometry[0] (id=\"0\") / coefs (line 9): missing geoDim attribute; expected geoDim=\"d\" with d >= 2"});
  check_message(error_for(xml(unit_cube("0", "geoDim=\"1\""))),
                {"/ coefs (line 9): geoDim=\"1\"; expected geoDim=\"d\" with d >= 2"});
  check_message(error_for(xml(unit_cube("0", "geoDim=\"4\""))),
                {"/ coefs (line 9): 24 numbers; expected 32 (2 x 2 x 2 control points x geoDim 4)"});
  std::string t = unit_cube();
  t.replace(t.find("1 1 1</coefs>"), 5, "1 1");
  check_message(error_for(xml(t)), {"/ coefs (line 9): 23 numbers; expected 24 (2 x 2 x 2 control points x geoDim 3)"});
  t = unit_cube();
  t.erase(t.find("<coefs"), t.find("</coefs>") + 8 - t.find("<coefs"));
  check_message(error_for(xml(t)), {"Geometry[0] (id=\"0\") (line 3): missing <coefs>; expected a <coefs geoDim=\"3\">"});
}

TEST_CASE("every geometry of a file has the same geoDim", "[io][gismo][bad]") {
  std::string second = unit_cube("1", "geoDim=\"4\"");
  second.replace(second.find("1 1 1</coefs>"), 5, "1 1 1 0 0 0 0 0 0 0 0");  // 32 numbers
  const std::string t = xml(unit_cube("0") + second);
  check_message(error_for(t), {"bad.xml: Geometry[1] (id=\"1\") / coefs (line 24): geoDim 4 (4 coordinates per point); expected 3 like Geometry[0] (id=\"0\")"});
}

TEST_CASE("NURBS weights: present, positive, one per control point", "[io][gismo][bad]") {
  auto nurbs = [](const std::string& weights) {
    return xml("<Geometry type=\"TensorNurbs2\" id=\"5\">\n<Basis type=\"TensorNurbsBasis2\">\n" +
               bspline_basis(2, "0 0 1 1", 1) + weights + "</Basis>\n" +
               "<coefs geoDim=\"3\">0 0 0\n1 0 0\n0 1 0\n1 1 0</coefs></Geometry>\n");
  };
  check_message(error_for(nurbs("")),
                {"bad.xml: Geometry[0] (id=\"5\") / Basis type=\"TensorNurbsBasis2\" (line 4): missing <weights>; expected a <weights> list"});
  check_message(error_for(nurbs("<weights>1 1 1</weights>\n")),
                {"/ Basis type=\"TensorNurbsBasis2\" / weights (line 9): 3 weights; expected 4 (one per control point)"});
  check_message(error_for(nurbs("<weights>1 1 0 1</weights>\n")),
                {"/ weights (line 9): weight 2 is 0; expected positive weights"});
  check_message(error_for(nurbs("<weights>1 -1 1 1</weights>\n")),
                {"/ weights (line 9): weight 1 is -1; expected positive weights"});
  std::string plain = nurbs("<weights>1 1 1 1</weights>\n");
  plain.replace(plain.find("TensorNurbsBasis2"), 17, "TensorBSplineBasis2");
  check_message(error_for(plain), {"Basis type=\"TensorBSplineBasis2\" (line 4): type=\"TensorBSplineBasis2\"; expected type=\"TensorNurbsBasis2\""});
}

// --------------------------------------------------------------------------------------------
// Robustness

TEST_CASE("truncated or corrupted G+Smo files only ever give trivox::Error", "[io][gismo][bad]") {
  const std::string text = slurp(source_dir() / "models" / "gismo" / "cube.xml");
  for (std::size_t n = 0; n < text.size(); n += 7) {
    try {
      read_gismo_xml(std::string_view(text).substr(0, n), "cut.xml");
    } catch (const trivox::Error& e) {
      CHECK_THAT(std::string(e.what()), Catch::StartsWith("cut.xml: "));
    }
  }
  std::mt19937 rng(11);
  const std::string alphabet = "<>/=\" 0123456789.-e\nabcGeometryBasisKnotVector";
  for (int trial = 0; trial < 2000; ++trial) {
    std::string t = text;
    for (int e = 0; e < 3; ++e) t[rng() % t.size()] = alphabet[rng() % alphabet.size()];
    try {
      read_gismo_xml(t, "fuzz.xml");
    } catch (const trivox::Error& e) {
      CHECK_THAT(std::string(e.what()), Catch::StartsWith("fuzz.xml: "));
    }
  }
}
