#include "trivox/io/gismo_xml.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <pugixml.hpp>

#include "trivox/error.hpp"

namespace trivox::io {

namespace {

using spline::KnotVector;

// ------------------------------------------------------------------------------------------
// Places in the file

/// An element with its human-readable path from the root, e.g.
/// `Geometry[3] (id="1") / Basis type="TensorBSplineBasis3" / Basis index="0" / KnotVector`.
struct Element {
  pugi::xml_node node;
  std::string path;
};

/// The file being read: every message starts with its name, an element path and a line.
struct Source {
  const std::string& name;
  std::string_view text;
  const Limits& limits;

  /// 1-based line of byte `offset`.
  std::size_t line_at(std::size_t offset) const {
    offset = std::min(offset, text.size());
    return 1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + offset, '\n'));
  }
  /// 1-based column of byte `offset`, in bytes.
  std::size_t column_at(std::size_t offset) const {
    offset = std::min(offset, text.size());
    const std::size_t nl = text.substr(0, offset).rfind('\n');
    return nl == std::string_view::npos ? offset + 1 : offset - nl;
  }

  std::string where(const Element& e) const {
    std::string s = name + ": " + e.path;
    if (const auto off = e.node.offset_debug(); off >= 0)
      s += " (line " + std::to_string(line_at(static_cast<std::size_t>(off))) + ")";
    return s;
  }

  [[noreturn]] void fail(const Element& e, const std::string& what) const {
    throw Error(where(e) + ": " + what);
  }
  /// A value over a limit: the message ends with the limit's name and how to raise it.
  [[noreturn]] void over(const Element& e, const std::string& what, const char* limit) const {
    throw Error(where(e) + ": " + what + limit_hint(limit));
  }
};

std::string quoted(std::string_view s) {
  // Appended piecewise: GCC 12 warns falsely (-Wrestrict) on "\"" + std::string(s) + "\"".
  std::string out;
  out.reserve(s.size() + 2);
  out.append(1, '"').append(s).append(1, '"');
  return out;
}

/// Shortest round-trip text of a double.
std::string num(double v) {
  char buf[32];
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
}

/// A path step: the element name and the attribute that tells it from its siblings.
std::string step(pugi::xml_node n) {
  std::string s = n.name();
  if (auto a = n.attribute("index")) return s + " index=" + quoted(a.value());
  if (auto a = n.attribute("type")) return s + " type=" + quoted(a.value());
  return s;
}

Element enter(const Element& parent, pugi::xml_node n) {
  return {n, parent.path + " / " + step(n)};
}

Element require_child(const Source& src, const Element& parent, const char* name,
                      const std::string& expected) {
  pugi::xml_node n = parent.node.child(name);
  if (!n) src.fail(parent, std::string("missing <") + name + ">; expected " + expected);
  return enter(parent, n);
}

void require_type(const Source& src, const Element& e, const std::string& type) {
  const std::string_view found = e.node.attribute("type").value();
  if (found != type) src.fail(e, "type=" + quoted(found) + "; expected type=" + quoted(type));
}

// ------------------------------------------------------------------------------------------
// Numbers in element text

/// A token shown in a message: short, printable ASCII only.
std::string show_token(std::string_view t) {
  std::string s(t.substr(0, 24));
  for (char& c : s)
    if (c < 0x20 || c > 0x7e) c = '?';
  return quoted(s) + (t.size() > 24 ? "..." : "");
}

/// All text directly inside the element (G+Smo writes one text node; CDATA is accepted too).
std::string text_of(pugi::xml_node n) {
  std::string s;
  for (pugi::xml_node c : n.children())
    if (c.type() == pugi::node_pcdata || c.type() == pugi::node_cdata) s += c.value();
  return s;
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

/// G+Smo writes numbers in ASCII unless told otherwise; other encodings are not supported.
void require_ascii(const Source& src, const Element& e) {
  if (auto f = e.node.attribute("format"); f && std::string_view(f.value()) != "ASCII")
    src.fail(e, "format=" + quoted(f.value()) +
                    "; expected format=\"ASCII\" (the only one trivox reads)");
}

/// How a token reads as a double.
enum class Parsed { number, not_finite, not_a_number };

Parsed parse_double(std::string_view tok, double& v) {
  // from_chars takes no leading '+', which hand-written files may have.
  if (tok.size() > 1 && tok[0] == '+') tok.remove_prefix(1);
  const char* end = tok.data() + tok.size();
  const auto r = std::from_chars(tok.data(), end, v);
  if (r.ptr != end || (r.ec != std::errc() && r.ec != std::errc::result_out_of_range))
    return Parsed::not_a_number;
  if (r.ec == std::errc::result_out_of_range) {
    // Overflow is an error; an underflow (1e-400: a negative exponent) is the nearest double,
    // a signed zero, as the JSON reader would have it.
    const bool underflow =
        tok.find("e-") != std::string_view::npos || tok.find("E-") != std::string_view::npos;
    if (!underflow) return Parsed::not_finite;
    v = tok[0] == '-' ? -0.0 : 0.0;
  }
  return std::isfinite(v) ? Parsed::number : Parsed::not_finite;
}

std::vector<double> read_numbers(const Source& src, const Element& e) {
  require_ascii(src, e);
  const std::string s = text_of(e.node);
  std::vector<double> out;
  std::size_t i = 0;
  while (true) {
    while (i < s.size() && is_space(s[i])) ++i;
    if (i == s.size()) return out;
    std::size_t j = i;
    while (j < s.size() && !is_space(s[j])) ++j;
    const std::string_view tok(s.data() + i, j - i);
    double v = 0;
    const Parsed p = parse_double(tok, v);
    if (p == Parsed::not_finite)
      src.fail(e, "number " + std::to_string(out.size()) + " " + show_token(tok) +
                      " is not finite; expected a finite number");
    if (p == Parsed::not_a_number)
      src.fail(e, "number " + std::to_string(out.size()) + " " + show_token(tok) +
                      " is not a number; expected numbers separated by white space");
    out.push_back(v);
    i = j;
  }
}

int read_int_attribute(const Source& src, const Element& e, const char* attr, int lo, int hi,
                       const std::string& expected) {
  pugi::xml_attribute a = e.node.attribute(attr);
  if (!a) src.fail(e, std::string("missing ") + attr + " attribute; expected " + expected);
  const std::string_view s = a.value();
  int v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec != std::errc() || r.ptr != s.data() + s.size() || v < lo || v > hi)
    src.fail(e, std::string(attr) + "=" + show_token(s) + "; expected " + expected);
  return v;
}

// ------------------------------------------------------------------------------------------
// Bases

KnotVector read_knot_vector(const Source& src, const Element& e) {
  // A degree near INT_MAX would overflow order arithmetic; no real file comes close.
  const int degree =
      read_int_attribute(src, e, "degree", 0, 1 << 20, "degree=\"p\" with 0 <= p <= 1048576");
  const int order = degree + 1;
  if (order > src.limits.max_order)
    src.over(e, "degree=" + quoted(std::to_string(degree)) + "; expected a degree of at most " +
                    std::to_string(src.limits.max_order - 1) + " (an order of at most " +
                    std::to_string(src.limits.max_order) + ")",
             "max_order");
  std::vector<double> knots = read_numbers(src, e);
  for (std::size_t i = 1; i < knots.size(); ++i)
    if (knots[i] < knots[i - 1])
      src.fail(e, "knot " + std::to_string(i) + " (" + num(knots[i]) + ") is less than knot " +
                      std::to_string(i - 1) + " (" + num(knots[i - 1]) +
                      "); expected non-decreasing knots");
  try {
    return KnotVector(order, std::move(knots));
  } catch (const Error& err) {
    throw err.within(src.where(e));
  }
}

/// The P knot vectors of a `TensorBSplineBasis<P>`, placed by their `index` attribute (or by
/// position when it is absent).
template <int P>
std::array<KnotVector, P> read_tensor_basis(const Source& src, const Element& basis) {
  require_type(src, basis, "TensorBSplineBasis" + std::to_string(P));
  std::array<KnotVector, P> knots;
  std::array<bool, P> seen{};
  int position = 0;
  const std::string max_index = std::to_string(P - 1);
  for (pugi::xml_node n : basis.node.children("Basis")) {
    const Element e = enter(basis, n);
    const int d = n.attribute("index") ? read_int_attribute(src, e, "index", 0, P - 1,
                                                            "an index from 0 to " + max_index)
                                       : position;
    if (d >= P)
      src.fail(e, "more than " + std::to_string(P) +
                      " BSplineBasis children; expected one per direction");
    if (seen[d])
      src.fail(e, "a second basis for direction " + std::to_string(d) +
                      "; expected one BSplineBasis per direction");
    require_type(src, e, "BSplineBasis");
    knots[d] =
        read_knot_vector(src, require_child(src, e, "KnotVector", "a <KnotVector degree=\"p\">"));
    seen[d] = true;
    ++position;
  }
  if (position != P)
    src.fail(basis, std::to_string(position) + " BSplineBasis children; expected " +
                        std::to_string(P) + ", one per direction");
  return knots;
}

// ------------------------------------------------------------------------------------------
// Geometries

/// The coordinate count a model's patches must share, set by the first patch.
struct DimRule {
  int dim = 0;
  std::string first;  ///< path of the geometry that set it
};

/// Product of counts, saturating: absurd counts must give a message, not an overflow.
std::int64_t saturating_product(std::int64_t a, std::int64_t b) {
  return (b != 0 && a > INT64_MAX / b) ? INT64_MAX : a * b;
}

/// Control points padded to the model's dimension `dim`: geoDim 2 is planar (z = 0).
std::vector<double> read_coefs(const Source& src, const Element& coefs, std::int64_t count,
                               const std::string& counts_text, int& geo_dim, int& dim) {
  geo_dim = read_int_attribute(src, coefs, "geoDim", 2, 1 << 16,
                               "geoDim=\"d\" with d >= 2 (coordinates per point)");
  if (geo_dim - 3 > src.limits.max_properties)
    src.over(coefs, "geoDim=" + quoted(std::to_string(geo_dim)) + " (" + std::to_string(geo_dim - 3) +
                        " properties); expected at most " + std::to_string(src.limits.max_properties) +
                        " properties, geoDim " + std::to_string(src.limits.max_properties + 3),
             "max_properties");
  const std::vector<double> v = read_numbers(src, coefs);
  const std::int64_t expected = saturating_product(geo_dim, count);
  if (static_cast<std::int64_t>(v.size()) != expected)
    src.fail(coefs, std::to_string(v.size()) + " numbers; expected " + std::to_string(expected) +
                        " (" + counts_text + " control points x geoDim " + std::to_string(geo_dim) +
                        ")");
  dim = std::max(3, geo_dim);
  if (geo_dim == dim) return v;
  std::vector<double> out;
  out.reserve(static_cast<std::size_t>(count) * 3);
  for (std::size_t i = 0; i < v.size(); i += 2) out.insert(out.end(), {v[i], v[i + 1], 0.0});
  return out;
}

std::vector<double> read_weights(const Source& src, const Element& e, std::int64_t count) {
  std::vector<double> w = read_numbers(src, e);
  if (static_cast<std::int64_t>(w.size()) != count)
    src.fail(e, std::to_string(w.size()) + " weights; expected " + std::to_string(count) +
                    " (one per control point)");
  for (std::size_t i = 0; i < w.size(); ++i)
    if (!(w[i] > 0))
      src.fail(e,
               "weight " + std::to_string(i) + " is " + num(w[i]) + "; expected positive weights");
  return w;
}

template <int P>
spline::TensorSpline<P> read_geometry(const Source& src, const Element& geom, bool rational,
                                      DimRule& rule) {
  const std::string ps = std::to_string(P);
  const std::string basis_what = rational ? "a <Basis type=\"TensorNurbsBasis" + ps + "\">"
                                          : "a <Basis type=\"TensorBSplineBasis" + ps + "\">";
  Element basis = require_child(src, geom, "Basis", basis_what);
  Element nurbs = basis;
  if (rational) {
    require_type(src, nurbs, "TensorNurbsBasis" + ps);
    basis = require_child(src, nurbs, "Basis", "a <Basis type=\"TensorBSplineBasis" + ps + "\">");
  }
  std::array<KnotVector, P> knots = read_tensor_basis<P>(src, basis);
  std::int64_t count = 1;
  std::string counts_text;
  for (int d = 0; d < P; ++d) {
    count = saturating_product(count, knots[d].size());
    counts_text += (d ? " x " : "") + std::to_string(knots[d].size());
  }
  if (count > src.limits.max_points)
    src.over(basis, counts_text + " control points (from the knot vectors); expected at most " +
                        std::to_string(src.limits.max_points) + " per patch",
             "max_points");
  std::vector<double> weights;
  if (rational)
    weights = read_weights(src, require_child(src, nurbs, "weights", "a <weights> list"), count);
  const Element coefs = require_child(src, geom, "coefs", "a <coefs geoDim=\"3\"> list");
  int geo_dim = 0, dim = 0;
  std::vector<double> points = read_coefs(src, coefs, count, counts_text, geo_dim, dim);
  if (rule.dim == 0) rule = {dim, geom.path};
  if (dim != rule.dim)
    src.fail(coefs, "geoDim " + std::to_string(geo_dim) + " (" + std::to_string(dim) +
                        " coordinates per point); expected " + std::to_string(rule.dim) + " like " +
                        rule.first + " (every patch of a model carries the same properties)");
  try {
    return spline::TensorSpline<P>(std::move(knots), dim, std::move(points), std::move(weights));
  } catch (const Error& err) {
    throw err.within(src.where(geom));
  }
}

/// What a `<Geometry type=..>` holds, or params 0 for types trivox does not read.
struct GeometryKind {
  int params = 0;
  bool rational = false;
};

GeometryKind geometry_kind(std::string_view type) {
  if (type == "TensorBSpline3") return {3, false};
  if (type == "TensorNurbs3") return {3, true};
  if (type == "TensorBSpline2") return {2, false};
  if (type == "TensorNurbs2") return {2, true};
  return {};
}

pugi::xml_node parse(const Source& src, pugi::xml_document& doc) {
  const pugi::xml_parse_result r =
      doc.load_buffer(src.text.data(), src.text.size(), pugi::parse_default, pugi::encoding_utf8);
  if (!r) {
    const auto off = static_cast<std::size_t>(std::max<std::ptrdiff_t>(r.offset, 0));
    throw Error(src.name + ": line " + std::to_string(src.line_at(off)) + ", column " +
                std::to_string(src.column_at(off)) + ": malformed XML: " + r.description() +
                "; expected well-formed XML");
  }
  const pugi::xml_node root = doc.document_element();
  if (std::string_view(root.name()) != "xml")
    src.fail({root, root.name()},
             std::string("root element <") + root.name() + ">; expected <xml> (a G+Smo file)");
  return root;
}

}  // namespace

vmodel::VModel read_gismo_xml(std::string_view text, const std::string& source, const Limits& limits) {
  const Source src{source, text, limits};
  pugi::xml_document doc;
  const Element root{parse(src, doc), "xml"};
  vmodel::VModel model;
  DimRule rule;
  int index = 0;
  for (pugi::xml_node g : root.node.children("Geometry")) {
    std::string path = "Geometry[" + std::to_string(index) + "]";
    if (auto id = g.attribute("id")) path += " (id=" + quoted(id.value()) + ")";
    const Element e{g, path};
    if (index >= limits.max_cells)
      src.over(e, "more than " + std::to_string(limits.max_cells) + " geometries; expected at most " +
                      std::to_string(limits.max_cells) + " cells and surfaces",
               "max_cells");
    const GeometryKind kind = geometry_kind(g.attribute("type").value());
    std::string name = std::string("patch").append(std::to_string(index++));
    if (kind.params == 3)
      model.cells.push_back({std::move(name), read_geometry<3>(src, e, kind.rational, rule)});
    else if (kind.params == 2)
      model.surfaces.push_back({std::move(name), read_geometry<2>(src, e, kind.rational, rule)});
    else
      src.fail(e, "geometry type=" + quoted(g.attribute("type").value()) +
                      "; expected TensorBSpline3, TensorNurbs3, TensorBSpline2 or TensorNurbs2");
  }
  if (index == 0)
    src.fail(root,
             "no <Geometry> elements; expected at least one TensorBSpline2/3 or "
             "TensorNurbs2/3 geometry");
  for (int p = 3; p < rule.dim; ++p)
    model.properties.push_back(std::string("p").append(std::to_string(p - 3)));
  return model;
}

}  // namespace trivox::io
