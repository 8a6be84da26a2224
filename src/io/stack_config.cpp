// ConfigFile.xml (stack_config.hpp): written and parsed with pugixml; slice file names.
#include "trivox/io/stack_config.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstring>
#include <fstream>
#include <pugixml.hpp>
#include <set>
#include <sstream>

#include "png_rows.hpp"
#include "trivox/error.hpp"
#include "trivox/io/model_file.hpp"

namespace trivox::io {

namespace fs = std::filesystem;

// ------------------------------------------------------------------------------------------------
// Names

std::string StackConfig::slice_name(int i) const {
  const long long n = static_cast<long long>(start_index) + i;
  std::string digits_text = std::to_string(n < 0 ? -n : n);
  if (static_cast<int>(digits_text.size()) < digits)
    digits_text.insert(0, static_cast<std::size_t>(digits) - digits_text.size(), '0');
  return prefix + (n < 0 ? "-" : "") + digits_text + ".png";
}

// ------------------------------------------------------------------------------------------------
// ConfigFile.xml

namespace {

std::string num(double v) {
  char buf[32];
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
}

/// A checked whole number (check_config: at most 1e9) as an integer: every reader of
/// ConfigFile.xml parses these elements as integers (voxelprint-preview: parseInt), so
/// `1000.9999999999999` would read as 1000 and `1e+05` as 1.
std::string integer(double v) { return std::to_string(std::llround(v)); }

bool whole(double v) { return std::isfinite(v) && v == std::floor(v); }

std::string in_quotes(std::string_view s) {
  std::string out;
  out.reserve(s.size() + 2);
  out.append(1, '"').append(s).append(1, '"');
  return out;
}

std::string_view trim(std::string_view s) {
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
  while (!s.empty() && space(s.front())) s.remove_prefix(1);
  while (!s.empty() && space(s.back())) s.remove_suffix(1);
  return s;
}

/// The canonical place of each element, for messages about missing ones.
const char* canonical(std::string_view name) {
  static const std::pair<const char*, const char*> places[] = {
      {"Version", "GCVF/Version"},
      {"XDpi", "GCVF/Resolution/XDpi"},
      {"YDpi", "GCVF/Resolution/YDpi"},
      {"SliceThicknessNanoMeter", "GCVF/Resolution/SliceThicknessNanoMeter"},
      {"SliceWidth", "GCVF/SliceDimensions/SliceWidth"},
      {"SliceHeight", "GCVF/SliceDimensions/SliceHeight"},
      {"StartIndex", "GCVF/SliceRange/StartIndex"},
      {"NumberOfSlices", "GCVF/SliceRange/NumberOfSlices"},
      {"BitDepth", "GCVF/BitDepth"},
      {"MaxNumberOfColors", "GCVF/MaxNumberOfColors"},
      {"DataSemantics", "GCVF/DataSemantics"},
      {"CreationMode", "GCVF/CreationMode"},
      {"ImageFilePrefix", "GCVF/ImageFilePrefix"},
      {"MaterialList", "GCVF/MaterialList"},
      {"BackGroundMaterialRGBA", "GCVF/MaterialList/BackGroundMaterialRGBA"},
  };
  for (const auto& [n, p] : places)
    if (name == n) return p;
  return "GCVF";
}

/// The file being read and its places: every message names the file, the element path and line.
struct XmlSource {
  const std::string& name;
  std::string_view text;

  std::size_t line_at(std::size_t offset) const {
    offset = std::min(offset, text.size());
    return 1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(offset), '\n'));
  }
  std::size_t column_at(std::size_t offset) const {
    offset = std::min(offset, text.size());
    const std::size_t nl = text.substr(0, offset).rfind('\n');
    return nl == std::string_view::npos ? offset + 1 : offset - nl;
  }
  /// "file: GCVF/MaterialList/Material[1]/RGBA (line 30)"
  std::string where(pugi::xml_node node) const {
    std::vector<std::string> parts;
    for (pugi::xml_node n = node; n && n.type() == pugi::node_element; n = n.parent()) {
      std::string part = n.name();
      if (part == "Material") {
        int i = 0;
        for (pugi::xml_node s = n.previous_sibling("Material"); s; s = s.previous_sibling("Material")) ++i;
        part += "[" + std::to_string(i) + "]";
      }
      parts.push_back(std::move(part));
    }
    std::string s = name + ": ";
    for (auto it = parts.rbegin(); it != parts.rend(); ++it) s += (it == parts.rbegin() ? "" : "/") + *it;
    if (const auto off = node.offset_debug(); off >= 0)
      s += " (line " + std::to_string(line_at(static_cast<std::size_t>(off))) + ")";
    return s;
  }
  [[noreturn]] void fail(pugi::xml_node node, const std::string& what) const { throw Error(where(node) + ": " + what); }
  [[noreturn]] void missing(pugi::xml_node parent, std::string_view child, const std::string& expected) const {
    if (!parent || parent.parent().type() == pugi::node_document)
      throw Error(name + ": " + canonical(child) + ": missing; expected " + expected);
    throw Error(where(parent) + ": no <" + std::string(child) + ">; expected " + expected);
  }
};

/// First element named `name` below `root` (any depth).
pugi::xml_node find(pugi::xml_node root, const char* name) {
  return root.find_node([name](pugi::xml_node n) { return n.type() == pugi::node_element && std::strcmp(n.name(), name) == 0; });
}

double number_in(const XmlSource& src, pugi::xml_node node, double lo, double hi, const std::string& expected) {
  const std::string_view t = trim(node.text().get());
  double v = 0;
  const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (t.empty() || ec != std::errc() || ptr != t.data() + t.size() || !std::isfinite(v))
    src.fail(node, in_quotes(t) + " is not a number; expected " + expected);
  if (!(v >= lo && v <= hi)) src.fail(node, num(v) + "; expected " + expected);
  return v;
}

long long integer_in(const XmlSource& src, pugi::xml_node node, long long lo, long long hi, const std::string& expected) {
  const std::string_view t = trim(node.text().get());
  long long v = 0;
  const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (t.empty() || ec != std::errc() || ptr != t.data() + t.size())
    src.fail(node, in_quotes(t) + " is not an integer; expected " + expected);
  if (v < lo || v > hi) src.fail(node, std::to_string(v) + "; expected " + expected);
  return v;
}

std::array<std::uint8_t, 4> rgba_in(const XmlSource& src, pugi::xml_node node) {
  const std::string expected = "four integers 0..255 \"r g b a\"";
  std::string_view t = trim(node.text().get());
  std::array<std::uint8_t, 4> out{};
  std::size_t k = 0;
  const std::string_view all = t;
  while (!t.empty()) {
    int v = -1;
    const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (ec != std::errc() || ptr == t.data() || k == 4 || v < 0 || v > 255)
      src.fail(node, in_quotes(all) + "; expected " + expected);
    out[k++] = static_cast<std::uint8_t>(v);
    t = trim(t.substr(static_cast<std::size_t>(ptr - t.data())));
    if (!t.empty() && t.front() == ',') t = trim(t.substr(1));  // "r, g, b, a" reads too
  }
  if (k != 4) src.fail(node, in_quotes(all) + "; expected " + expected);
  return out;
}

/// Ranges every config must respect, written and read alike.
constexpr double max_dpi = 100000;
constexpr double max_thickness_nm = 1e9;
constexpr int max_pixels = 1000000;
// A metre of 1 um layers; a J750 tray is 7407 layers of 27 um. The bound keeps a malformed file
// from making inspect or preview plan billions of slices.
constexpr int max_slices = 1000000;
const std::string slices_expected = "a slice count of 1..1000000 (and StartIndex + NumberOfSlices within 2^31)";
const std::string dpi_expected = "a positive number of pixels per inch, at most 100000";
const std::string thickness_expected = "a positive layer thickness in nanometres, at most 1e9 (1 m)";
const std::string size_expected = "a whole number of pixels, 1..1000000";
const std::string prefix_expected = "a file-name prefix without '/', '\\' or NUL";

bool prefix_ok(std::string_view p) { return p.find_first_of(std::string_view("/\\\0", 3)) == std::string_view::npos && p != ".."; }

/// Checks what the XML cannot express wrongly once parsed, for config_xml's input.
void check_config(const StackConfig& c) {
  const auto bad = [](const std::string& what) { throw Error("ConfigFile.xml: " + what); };
  if (c.version < 1) bad("Version " + std::to_string(c.version) + "; expected a positive format version (2)");
  if (!(c.dpi_x > 0 && c.dpi_x <= max_dpi)) bad("XDpi " + num(c.dpi_x) + "; expected " + dpi_expected);
  if (!(c.dpi_y > 0 && c.dpi_y <= max_dpi)) bad("YDpi " + num(c.dpi_y) + "; expected " + dpi_expected);
  if (!(c.slice_thickness_nm > 0 && c.slice_thickness_nm <= max_thickness_nm))
    bad("SliceThicknessNanoMeter " + num(c.slice_thickness_nm) + "; expected " + thickness_expected);
  if (!whole(c.dpi_x) || !whole(c.dpi_y))
    bad("XDpi, YDpi " + num(c.dpi_x) + ", " + num(c.dpi_y) + "; expected whole dots per inch (readers take integers)");
  if (!whole(c.slice_thickness_nm))
    bad("SliceThicknessNanoMeter " + num(c.slice_thickness_nm) + "; expected a whole number of nanometres (readers take an integer)");
  if (c.max_colors < 1) bad("MaxNumberOfColors " + std::to_string(c.max_colors) + "; expected 1 or more");
  if (static_cast<int>(c.materials.size()) > c.max_colors) {
    std::string names;
    for (const StackMaterial& m : c.materials) names += (names.empty() ? "" : ", ") + m.name;
    bad("MaterialList: " + std::to_string(c.materials.size()) + " materials (" + names + "); expected at most " +
        std::to_string(c.max_colors) + ", the printer's MaxNumberOfColors");
  }
  if (c.width < 1 || c.width > max_pixels) bad("SliceWidth " + std::to_string(c.width) + "; expected " + size_expected);
  if (c.height < 1 || c.height > max_pixels) bad("SliceHeight " + std::to_string(c.height) + "; expected " + size_expected);
  if (c.start_index < 0) bad("StartIndex " + std::to_string(c.start_index) + "; expected 0 or more");
  if (c.slices < 1 || c.slices > max_slices || static_cast<long long>(c.start_index) + c.slices - 1 > INT_MAX)
    bad("NumberOfSlices " + std::to_string(c.slices) + "; expected " + slices_expected);
  if (!prefix_ok(c.prefix)) bad("ImageFilePrefix " + in_quotes(c.prefix) + "; expected " + prefix_expected);
  std::set<std::array<std::uint8_t, 4>> seen;
  for (std::size_t i = 0; i < c.materials.size(); ++i) {
    const StackMaterial& m = c.materials[i];
    const std::string at = "MaterialList/Material[" + std::to_string(i) + "] " + in_quotes(m.name) + ": ";
    if (m.name.empty()) bad(at + "empty Name; expected the material's name");
    if (m.rgba[3] == 0) bad(at + "RGBA " + detail::rgba_text(m.rgba.data()) + " is transparent; expected alpha > 0 (alpha 0 is void)");
    if (m.rgba == c.background) bad(at + "RGBA " + detail::rgba_text(m.rgba.data()) + " is the background colour; expected a colour of its own");
    if (!seen.insert(m.rgba).second) bad(at + "RGBA " + detail::rgba_text(m.rgba.data()) + " repeats an earlier material's; expected distinct colours");
    if (m.voxel_count < 0) bad(at + "VoxelCount " + std::to_string(m.voxel_count) + "; expected 0 or more");
  }
}

void text_child(pugi::xml_node parent, const char* name, const std::string& value) {
  parent.append_child(name).text().set(value.c_str());
}

}  // namespace

std::array<std::uint8_t, 4> stack_background(std::string_view name) {
  if (name == "transparent") return {0, 0, 0, 0};
  if (name == "black") return {0, 0, 0, 255};
  throw Error("--background " + std::string(name) + ": unknown; expected transparent or black");
}

std::string stack_background_name(const std::array<std::uint8_t, 4>& rgba) {
  if (rgba == std::array<std::uint8_t, 4>{0, 0, 0, 0}) return "transparent";
  if (rgba == std::array<std::uint8_t, 4>{0, 0, 0, 255}) return "black";
  return detail::rgba_text(rgba.data());
}

std::string config_xml(const StackConfig& c) {
  check_config(c);
  pugi::xml_document doc;
  pugi::xml_node decl = doc.append_child(pugi::node_declaration);
  decl.append_attribute("version") = "1.0";
  decl.append_attribute("encoding") = "UTF-8";
  doc.append_child(pugi::node_comment).set_value(" GCVF - GrabCAD Voxel Print slice folder, written by trivox ");
  pugi::xml_node root = doc.append_child("GCVF");
  text_child(root, "Version", std::to_string(c.version));
  pugi::xml_node res = root.append_child("Resolution");
  text_child(res, "XDpi", integer(c.dpi_x));
  text_child(res, "YDpi", integer(c.dpi_y));
  text_child(res, "SliceThicknessNanoMeter", integer(c.slice_thickness_nm));
  pugi::xml_node dims = root.append_child("SliceDimensions");
  text_child(dims, "SliceWidth", std::to_string(c.width));
  text_child(dims, "SliceHeight", std::to_string(c.height));
  pugi::xml_node range = root.append_child("SliceRange");
  text_child(range, "StartIndex", std::to_string(c.start_index));
  text_child(range, "NumberOfSlices", std::to_string(c.slices));
  text_child(root, "BitDepth", std::to_string(c.bit_depth));
  text_child(root, "MaxNumberOfColors", std::to_string(c.max_colors));
  text_child(root, "DataSemantics", c.data_semantics);
  text_child(root, "CreationMode", c.creation_mode);
  text_child(root, "ImageFilePrefix", c.prefix);
  pugi::xml_node list = root.append_child("MaterialList");
  text_child(list, "BackGroundMaterialRGBA", detail::rgba_text(c.background.data()));
  for (const StackMaterial& m : c.materials) {
    pugi::xml_node e = list.append_child("Material");
    text_child(e, "Name", m.name);
    text_child(e, "RGBA", detail::rgba_text(m.rgba.data()));
    text_child(e, "VoxelCount", std::to_string(m.voxel_count));
  }
  std::ostringstream s;
  doc.save(s, "  ", pugi::format_default, pugi::encoding_utf8);
  return std::move(s).str();
}

StackConfig parse_config_xml(std::string_view text, const std::string& source) {
  const XmlSource src{source, text};
  pugi::xml_document doc;
  const pugi::xml_parse_result r = doc.load_buffer(text.data(), text.size(), pugi::parse_default, pugi::encoding_utf8);
  if (!r) {
    const auto off = static_cast<std::size_t>(std::max<std::ptrdiff_t>(r.offset, 0));
    throw Error(source + ": line " + std::to_string(src.line_at(off)) + ", column " + std::to_string(src.column_at(off)) +
                ": malformed XML: " + r.description() + "; expected a well-formed GCVF ConfigFile.xml");
  }
  const pugi::xml_node root = doc.document_element();
  if (!root) throw Error(source + ": no root element; expected <GCVF> with the stack's configuration");

  const auto required = [&](const char* name, const std::string& expected) {
    const pugi::xml_node n = find(root, name);
    if (!n) src.missing(root, name, "<" + std::string(name) + "> with " + expected);
    return n;
  };
  StackConfig c;
  c.version = static_cast<int>(integer_in(src, required("Version", "the format version"), 1, INT_MAX, "a positive format version (2)"));
  c.dpi_x = number_in(src, required("XDpi", dpi_expected), 1e-300, max_dpi, dpi_expected);
  c.dpi_y = number_in(src, required("YDpi", dpi_expected), 1e-300, max_dpi, dpi_expected);
  c.slice_thickness_nm = number_in(src, required("SliceThicknessNanoMeter", thickness_expected), 1e-300, max_thickness_nm, thickness_expected);
  c.width = static_cast<int>(integer_in(src, required("SliceWidth", size_expected), 1, max_pixels, size_expected));
  c.height = static_cast<int>(integer_in(src, required("SliceHeight", size_expected), 1, max_pixels, size_expected));
  c.start_index = static_cast<int>(integer_in(src, required("StartIndex", "the first slice number"), 0, INT_MAX, "a slice number, 0 or more"));
  const long long most = std::min<long long>(max_slices, static_cast<long long>(INT_MAX) - c.start_index + 1);
  c.slices = static_cast<int>(integer_in(src, required("NumberOfSlices", "the slice count"), 1, most, slices_expected));
  const pugi::xml_node prefix = required("ImageFilePrefix", "the slice file-name prefix");
  c.prefix = trim(prefix.text().get());
  if (!prefix_ok(c.prefix)) src.fail(prefix, in_quotes(c.prefix) + "; expected " + prefix_expected);
  if (const auto n = find(root, "BitDepth")) c.bit_depth = static_cast<int>(integer_in(src, n, 0, 64, "an integer 0..64"));
  if (const auto n = find(root, "MaxNumberOfColors"))
    c.max_colors = static_cast<int>(integer_in(src, n, 0, INT_MAX, "a non-negative integer"));
  if (const auto n = find(root, "DataSemantics")) c.data_semantics = trim(n.text().get());
  if (const auto n = find(root, "CreationMode")) c.creation_mode = trim(n.text().get());

  const pugi::xml_node list = required("MaterialList", "a <Material> per material");
  if (const auto n = find(list, "BackGroundMaterialRGBA")) c.background = rgba_in(src, n);
  std::vector<pugi::xml_node> colour_nodes;
  for (pugi::xml_node m = list.child("Material"); m; m = m.next_sibling("Material")) {
    StackMaterial mat;
    const pugi::xml_node name = m.child("Name");
    if (!name) src.missing(m, "Name", "the material's name");
    mat.name = trim(name.text().get());
    if (mat.name.empty()) src.fail(name, "empty; expected the material's name (e.g. VeroCyan-V)");
    const pugi::xml_node rgba = m.child("RGBA");
    if (!rgba) src.missing(m, "RGBA", "the material's colour in the slices, \"r g b a\"");
    mat.rgba = rgba_in(src, rgba);
    if (mat.rgba[3] == 0) src.fail(rgba, in_quotes(detail::rgba_text(mat.rgba.data())) + " is transparent; expected alpha > 0 (alpha 0 is void)");
    if (mat.rgba == c.background)
      src.fail(rgba, in_quotes(detail::rgba_text(mat.rgba.data())) + " is the background (void) colour; expected a colour of its own");
    for (std::size_t k = 0; k < c.materials.size(); ++k)
      if (c.materials[k].rgba == mat.rgba)
        src.fail(rgba, in_quotes(detail::rgba_text(mat.rgba.data())) + " is also the colour of " + in_quotes(c.materials[k].name) +
                           "; expected distinct colours");
    const pugi::xml_node count = m.child("VoxelCount");
    if (!count) src.missing(m, "VoxelCount", "the material's voxel count");
    mat.voxel_count = integer_in(src, count, 0, LLONG_MAX, "a voxel count, 0 or more");
    c.materials.push_back(std::move(mat));
  }
  return c;
}

namespace {

[[noreturn]] void no_stack(const fs::path& dir, const std::string& what) {
  throw Error(dir.string() + ": " + what + "; expected a slice folder holding ConfigFile.xml (written by trivox slice)");
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw Error(p.string() + ": cannot open: " + std::strerror(errno) + "; expected a readable file");
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw Error(p.string() + ": cannot read: " + std::strerror(errno) + "; expected a readable file");
  return std::move(s).str();
}

}  // namespace

StackConfig read_stack_config(const fs::path& dir) {
  std::error_code ec;
  const fs::file_status st = fs::status(dir, ec);
  if (!fs::exists(st)) no_stack(dir, "no such folder");
  if (!fs::is_directory(st)) no_stack(dir, "is a file, not a folder");
  const fs::path file = dir / "ConfigFile.xml";
  if (!fs::exists(fs::status(file, ec))) no_stack(dir, "no ConfigFile.xml");
  if (fs::is_directory(file, ec)) no_stack(dir, "ConfigFile.xml is a folder");
  StackConfig c = parse_config_xml(slurp(file), file.string());
  const auto files = detail::list_slices(dir, c.prefix);
  auto first = files.lower_bound(c.start_index);
  if (first == files.end()) first = files.begin();
  if (first != files.end()) c.digits = static_cast<int>(first->second.size() - c.prefix.size() - 4);
  return c;
}

void write_stack_config(const fs::path& dir, const StackConfig& config) {
  write_file_atomically(dir / "ConfigFile.xml", config_xml(config));
}

}  // namespace trivox::io
