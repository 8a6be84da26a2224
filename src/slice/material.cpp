#include "trivox/slice/material.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>

#include "../detail/json_text.hpp"
#include <sstream>

#include "trivox/error.hpp"

namespace trivox::slice {

namespace {

using nlohmann::json;

constexpr std::size_t max_name_length = 64;
constexpr const char* name_rule =
    "a name of 1 to 64 characters from A-Z a-z 0-9 - _ . + ( ) and inner spaces";

// ------------------------------------------------------------------------------------------
// Messages: "<file>: <JSON pointer>: found ...; expected ..."

std::string quote(const std::string& s) { return detail::json_quote(s); }

std::string describe(const json& j) { return detail::json_describe(j); }

struct Source {
  const std::string& name;

  [[noreturn]] void fail(const std::string& ptr, const std::string& what) const {
    throw Error(name + ": " + (ptr.empty() ? std::string("top level") : ptr) + ": " + what);
  }
  [[noreturn]] void fail_type(const std::string& ptr, const json& j, const std::string& expected) const {
    fail(ptr, "found " + describe(j) + "; expected " + expected);
  }
};

json parse_json(const Source& src, std::string_view text) { return detail::parse_json_text(text, src.name); }

bool valid_name(const std::string& s) {
  if (s.empty() || s.size() > max_name_length || s.front() == ' ' || s.back() == ' ') return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    const bool alnum = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
    return alnum || std::strchr("-_.+() ", c) != nullptr;
  });
}

/// A key as a JSON pointer token (RFC 6901: ~ as ~0, / as ~1), printable ASCII only.
std::string pointer_token(const std::string& key) {
  std::string t;
  for (char c : key.substr(0, 40)) {
    if (c == '~') t += "~0";
    else if (c == '/') t += "~1";
    else t += static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f ? '?' : c;
  }
  return key.size() > 40 ? t + "..." : t;
}

/// Object keys outside `known` are errors: a misspelt "defualt" must not pass silently.
void check_keys(const Source& src, const json& obj, const std::string& ptr,
                std::initializer_list<const char*> known) {
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    const std::string& key = it.key();
    if (std::any_of(known.begin(), known.end(), [&](const char* k) { return key == k; })) continue;
    std::string list;
    for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
    src.fail(ptr + "/" + pointer_token(key), "unknown key " + quote(key) + "; expected one of " + list);
  }
}

const json* find(const json& obj, const char* key) {
  const auto it = obj.find(key);
  return it == obj.end() ? nullptr : &*it;
}

std::string read_name(const Source& src, const json& j, const std::string& ptr) {
  if (!j.is_string() || !valid_name(j.get<std::string>())) src.fail_type(ptr, j, name_rule);
  return j.get<std::string>();
}

int read_channel(const Source& src, const json& j, const std::string& ptr, int lo) {
  const std::string expected = "an integer " + std::to_string(lo) + "..255" +
                               (lo > 0 ? " (alpha 0 is void, which is not a material)" : "");
  if (!j.is_number()) src.fail_type(ptr, j, expected);
  const double v = j.get<double>();
  if (!(v == std::floor(v) && v >= lo && v <= 255)) src.fail_type(ptr, j, expected);
  return static_cast<int>(v);
}

std::string rgba_text(const std::array<std::uint8_t, 4>& c) {
  std::string s = "[";  // appending, not "[" + ...: GCC 12 warns falsely (-Wrestrict) on that
  for (int i = 0; i < 4; ++i) (s += std::to_string(c[static_cast<std::size_t>(i)])) += i < 3 ? "," : "]";
  return s;
}

Material read_material(const Source& src, const json& j, const std::string& ptr) {
  if (!j.is_object()) src.fail_type(ptr, j, "an object {\"name\": ..., \"rgba\": [r, g, b, a]}");
  check_keys(src, j, ptr, {"name", "rgba", "description"});
  Material m;
  const json* name = find(j, "name");
  if (!name) src.fail(ptr, "missing \"name\"; expected " + std::string(name_rule));
  m.name = read_name(src, *name, ptr + "/name");
  if (m.name == "r" || m.name == "g" || m.name == "b")
    src.fail(ptr + "/name", "found " + quote(m.name) +
                                "; expected a name other than r, g and b (the colour properties)");
  const json* rgba = find(j, "rgba");
  const std::string rgba_rule = "an array [r, g, b, a] of integers 0..255 (a > 0; [r, g, b] means a = 255)";
  if (!rgba) src.fail(ptr, "missing \"rgba\"; expected " + rgba_rule);
  if (!rgba->is_array() || rgba->size() < 3 || rgba->size() > 4) src.fail_type(ptr + "/rgba", *rgba, rgba_rule);
  m.rgba = {0, 0, 0, 255};
  for (std::size_t c = 0; c < rgba->size(); ++c)
    m.rgba[c] = static_cast<std::uint8_t>(read_channel(src, (*rgba)[c], ptr + "/rgba/" + std::to_string(c), c == 3 ? 1 : 0));
  return m;
}

int material_named(const Source& src, const Palette& p, const json& j, const std::string& ptr) {
  const std::string name = read_name(src, j, ptr);
  const int i = p.find(name);
  if (i < 0) {
    std::string list;
    for (std::size_t k = 0; k < p.materials.size() && k < 8; ++k) list += (k ? ", " : "") + p.materials[k].name;
    if (p.materials.size() > 8) list += ", ... (" + std::to_string(p.materials.size()) + " materials)";
    src.fail(ptr, "found " + quote(name) + "; expected the name of a palette material (" + list + ")");
  }
  return i;
}

/// The r, g, b conversion (docs/materials.md), shared with the fused kernels.
[[gnu::always_inline]] inline void cmykw(float r, float g, float b, float* f) noexcept { cmykw_fractions(r, g, b, f); }

/// An explicit fraction: negative and NaN become 0, and huge values stay finite when summed.
inline float clamp_fraction(float v) noexcept { return v > 0.0f ? (v < 1e30f ? v : 1e30f) : 0.0f; }

}  // namespace

// ------------------------------------------------------------------------------------------
// Palette

int Palette::find(std::string_view wanted) const {
  for (std::size_t i = 0; i < materials.size(); ++i)
    if (materials[i].name == wanted) return static_cast<int>(i);
  return -1;
}

Palette default_palette() {
  Palette p;
  p.name = "vero";
  p.materials = {{"VeroCyan-V", {0, 137, 166, 255}},     {"VeroMagenta-V", {198, 0, 88, 255}},
                 {"VeroYellow-V", {240, 197, 0, 255}},   {"VeroBlack", {26, 26, 29, 255}},
                 {"VeroUltraWhite", {255, 255, 255, 255}}, {"UltraClear", {137, 137, 137, 255}}};
  p.default_material = 4;
  return p;
}

Palette parse_palette(std::string_view json_text, const std::string& source) {
  const Source src{source};
  const json root = parse_json(src, json_text);
  if (!root.is_object()) src.fail_type("", root, "an object {\"trivox_palette\": 1, \"materials\": [...]}");
  const json* version = find(root, "trivox_palette");
  if (!version) {
    const bool model = find(root, "trivox") != nullptr;
    src.fail("", std::string("missing \"trivox_palette\"; expected 1 (a trivox palette file") +
                     (model ? "; this looks like a model file)" : ")"));
  }
  if (!version->is_number() || version->get<double>() != 1.0)
    src.fail_type("/trivox_palette", *version, "1 (the only palette format version)");
  check_keys(src, root, "", {"trivox_palette", "name", "description", "materials", "default", "rgb_materials"});

  Palette p;
  if (const json* name = find(root, "name")) p.name = read_name(src, *name, "/name");

  const json* list = find(root, "materials");
  const std::string list_rule = "an array of 1 to 254 materials {\"name\": ..., \"rgba\": [r, g, b, a]}";
  if (!list) src.fail("", "missing \"materials\"; expected " + list_rule);
  if (!list->is_array() || list->empty() || list->size() > static_cast<std::size_t>(max_palette_materials))
    src.fail_type("/materials", *list, list_rule);
  for (std::size_t i = 0; i < list->size(); ++i) {
    const std::string ptr = "/materials/" + std::to_string(i);
    Material m = read_material(src, (*list)[i], ptr);
    for (std::size_t k = 0; k < p.materials.size(); ++k) {
      const Material& o = p.materials[k];
      if (o.name == m.name)
        src.fail(ptr + "/name", "found " + quote(m.name) + ", the name of /materials/" + std::to_string(k) +
                                    " too; expected unique material names");
      if (o.rgba == m.rgba)
        src.fail(ptr + "/rgba", "found " + rgba_text(m.rgba) + ", the colour of /materials/" + std::to_string(k) +
                                    " (" + o.name + ") too; expected a colour unique to each material");
    }
    p.materials.push_back(std::move(m));
  }

  p.default_material = 0;
  if (const json* d = find(root, "default")) p.default_material = material_named(src, p, *d, "/default");

  if (const json* rgb = find(root, "rgb_materials")) {
    const std::string rule =
        "an object naming the palette materials \"cyan\", \"magenta\", \"yellow\", \"black\" and \"white\"";
    if (!rgb->is_object()) src.fail_type("/rgb_materials", *rgb, rule);
    check_keys(src, *rgb, "/rgb_materials", {"cyan", "magenta", "yellow", "black", "white"});
    ColourMaterials& c = p.rgb_materials;
    const std::array<std::pair<const char*, std::string*>, 5> roles = {
        {{"cyan", &c.cyan}, {"magenta", &c.magenta}, {"yellow", &c.yellow}, {"black", &c.black}, {"white", &c.white}}};
    for (const auto& [key, target] : roles) {
      const json* j = find(*rgb, key);
      if (!j) src.fail("/rgb_materials", std::string("missing \"") + key + "\"; expected " + rule);
      *target = p.materials[static_cast<std::size_t>(material_named(src, p, *j, std::string("/rgb_materials/") + key))].name;
    }
  }
  return p;
}

Palette load_palette(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec))
    throw Error(name + ": is a folder; expected a palette file (JSON)");
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    const int err = errno;
    throw Error(name + ": cannot open: " + (std::filesystem::exists(file, ec) ? std::strerror(err) : "no such file") +
                "; expected a readable palette file (JSON)");
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw Error(name + ": cannot read; expected a readable palette file (JSON)");
  return parse_palette(text.str(), name);
}

std::string palette_json(const Palette& palette) {
  auto s = [](const std::string& v) { return quote(v); };
  std::string out = "{\n  \"trivox_palette\": 1,\n  \"name\": " + s(palette.name) + ",\n  \"materials\": [\n";
  for (std::size_t i = 0; i < palette.materials.size(); ++i) {
    const Material& m = palette.materials[i];
    out += "    {\"name\": " + s(m.name) + ", \"rgba\": [" + std::to_string(m.rgba[0]) + ", " +
           std::to_string(m.rgba[1]) + ", " + std::to_string(m.rgba[2]) + ", " + std::to_string(m.rgba[3]) + "]}" +
           (i + 1 < palette.materials.size() ? ",\n" : "\n");
  }
  out += "  ],\n";
  const auto d = static_cast<std::size_t>(palette.default_material);
  out += "  \"default\": " + s(d < palette.materials.size() ? palette.materials[d].name : std::string()) + ",\n";
  // "rgb_materials" must name materials of the palette. A palette read without the key keeps the
  // default Vero names, which need not be among its materials (they are checked when used); the
  // key is then left out, and reading the file gives the same defaults back.
  const ColourMaterials& c = palette.rgb_materials;
  const bool named = palette.find(c.cyan) >= 0 && palette.find(c.magenta) >= 0 && palette.find(c.yellow) >= 0 &&
                     palette.find(c.black) >= 0 && palette.find(c.white) >= 0;
  if (!named && !(c == ColourMaterials{}))
    throw Error("cannot write the palette: rgb_materials names a material the palette does not have; expected the "
                "names of palette materials, or the defaults");
  if (!named) {
    out.erase(out.size() - 2);  // the last ",\n"
    return out + "\n}\n";
  }
  out += "  \"rgb_materials\": {\"cyan\": " + s(c.cyan) + ", \"magenta\": " + s(c.magenta) + ", \"yellow\": " +
         s(c.yellow) + ", \"black\": " + s(c.black) + ", \"white\": " + s(c.white) + "}\n}\n";
  return out;
}

// ------------------------------------------------------------------------------------------
// Colour conversion and mapping

std::array<float, 5> rgb_to_cmykw(float r, float g, float b) noexcept {
  std::array<float, 5> f{};
  cmykw(r, g, b, f.data());
  return f;
}

MaterialMapper::MaterialMapper(const Palette& palette, const std::vector<std::string>& property_names) {
  if (palette.materials.empty() || palette.materials.size() > static_cast<std::size_t>(max_palette_materials))
    throw Error("palette " + quote(palette.name) + ": " + std::to_string(palette.materials.size()) +
                " materials; expected 1 to 254");
  if (palette.default_material < 0 || palette.default_material >= static_cast<int>(palette.materials.size()))
    throw Error("palette " + quote(palette.name) + ": default material index " +
                std::to_string(palette.default_material) + "; expected an index into its materials");
  materials_ = static_cast<int>(palette.materials.size());
  properties_ = static_cast<int>(property_names.size());
  default_ = palette.default_material;

  std::array<int, 3> rgb{-1, -1, -1};
  std::vector<std::string> ignored, driven;
  for (int i = 0; i < properties_; ++i) {
    const std::string& name = property_names[static_cast<std::size_t>(i)];
    if (const int m = palette.find(name); m >= 0) {
      explicit_.push_back({i, m});
      driven.push_back(name);
    } else if (name == "r" || name == "g" || name == "b") {
      rgb[name == "r" ? 0 : name == "g" ? 1 : 2] = i;
    } else {
      ignored.push_back(name);
    }
  }
  rgb_ = rgb[0] >= 0 && rgb[1] >= 0 && rgb[2] >= 0;
  if (!rgb_)  // a lone r or g (a radius, say) is just another property
    for (int c = 0; c < 3; ++c)
      if (rgb[static_cast<std::size_t>(c)] >= 0) ignored.push_back(std::string(1, "rgb"[c]));

  std::string text;
  if (rgb_) {
    rgb_props_ = rgb;
    const ColourMaterials& c = palette.rgb_materials;
    const std::array<const std::string*, 5> names = {&c.cyan, &c.magenta, &c.yellow, &c.black, &c.white};
    std::string missing;
    for (std::size_t k = 0; k < 5; ++k) {
      cmykw_[k] = palette.find(*names[k]);
      if (cmykw_[k] < 0) missing += (missing.empty() ? "" : ", ") + *names[k];
    }
    if (!missing.empty())
      throw Error("palette " + quote(palette.name) + ": the model's colour properties r, g, b need the materials " +
                  c.cyan + ", " + c.magenta + ", " + c.yellow + ", " + c.black + " and " + c.white +
                  "; the palette lacks " + missing +
                  "; expected a palette holding them (or naming others in \"rgb_materials\")");
    text = "r,g,b -> " + c.cyan + "/" + c.magenta + "/" + c.yellow + "/" + c.black + "/" + c.white +
           " (subtractive CMYK + white)";
  }
  for (const std::string& d : driven) text += (text.empty() ? "" : "; ") + d + " -> " + d;
  if (!rgb_ && !explicit_.empty()) text += " (fractions)";
  const std::string& def = palette.materials[static_cast<std::size_t>(default_)].name;
  if (text.empty()) text = "no material properties: every voxel prints " + def;
  else text += "; default " + def;
  if (!ignored.empty()) {
    text += "; ignored:";
    for (std::size_t i = 0; i < ignored.size(); ++i) text += (i ? "," : " ") + ignored[i];
  }
  describe_ = std::move(text);
}

MaterialMapper::MaterialMapper(const Palette& palette, const std::vector<std::string>& property_names,
                               const std::string& source) try : MaterialMapper(palette, property_names) {
} catch (const Error& e) {
  if (source.empty()) throw;
  throw e.within(source);
}

void MaterialMapper::fractions(const float* props, float* out) const noexcept {
  std::fill(out, out + materials_, 0.0f);
  float sum = 0.0f;
  for (const Explicit& e : explicit_) {
    const float v = clamp_fraction(props[e.property]);
    out[e.material] += v;
    sum += v;
  }
  if (rgb_ && sum < 1.0f) {
    // Explicit materials first; the colour fills what they leave.
    float f[5];
    cmykw(props[rgb_props_[0]], props[rgb_props_[1]], props[rgb_props_[2]], f);
    const float rest = 1.0f - sum;
    for (int k = 0; k < 5; ++k) out[cmykw_[static_cast<std::size_t>(k)]] += rest * f[k];
    return;
  }
  if (sum > 0.0f) {
    const float inv = 1.0f / sum;
    for (int m = 0; m < materials_; ++m) out[m] *= inv;
    return;
  }
  out[default_] = 1.0f;
}

void MaterialMapper::fractions(const float* props, std::size_t count, float* out) const noexcept {
  const auto np = static_cast<std::size_t>(properties_), nm = static_cast<std::size_t>(materials_);
  for (std::size_t v = 0; v < count; ++v) fractions(props + v * np, out + v * nm);
}

void MaterialMapper::fractions(const float* props, const std::int32_t* cell, std::size_t count,
                               float* out) const noexcept {
  const auto np = static_cast<std::size_t>(properties_), nm = static_cast<std::size_t>(materials_);
  if (rgb_ && explicit_.empty()) {
    // Colour only: the same as fractions() per voxel (rest = 1, nothing to add to), inlined.
    const std::size_t ir = static_cast<std::size_t>(rgb_props_[0]), ig = static_cast<std::size_t>(rgb_props_[1]),
                      ib = static_cast<std::size_t>(rgb_props_[2]);
    auto run = [&]<std::size_t NM>() {
      const std::size_t n = NM > 0 ? NM : nm;
      for (std::size_t v = 0; v < count; ++v) {
        if (cell[v] < 0) continue;
        const float* p = props + v * np;
        float* o = out + v * n;
        float f[5];
        cmykw(p[ir], p[ig], p[ib], f);
        for (std::size_t k = 0; k < n; ++k) o[k] = 0.0f;
        for (std::size_t k = 0; k < 5; ++k) o[cmykw_[k]] = f[k];
      }
    };
    // The palette's size as a constant for the common ones: no memset call per voxel.
    if (nm == 5) run.operator()<5>();
    else if (nm == 6) run.operator()<6>();
    else if (nm == 7) run.operator()<7>();
    else if (nm == 8) run.operator()<8>();
    else run.operator()<0>();
    return;
  }
  for (std::size_t v = 0; v < count; ++v)
    if (cell[v] >= 0) fractions(props + v * np, out + v * nm);
}

std::string MaterialMapper::describe() const { return describe_; }

}  // namespace trivox::slice
