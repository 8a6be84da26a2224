#include "trivox/job/manifest.hpp"

#include <algorithm>
#include <charconv>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <map>
#include <nlohmann/json.hpp>

#include "../detail/json_text.hpp"
#include "trivox/error.hpp"
#include "trivox/io/gcvf.hpp"
#include "trivox/job/archive_mesh.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/io/safe_path.hpp"
#include "trivox/io/sha256.hpp"

namespace trivox::job {

namespace {

using ojson = nlohmann::ordered_json;
using json = nlohmann::json;

constexpr int manifest_version = 1;
constexpr int journal_version = 1;
constexpr int max_shards = 100000;
/// A manifest takes about 250 bytes per layer: 256 MiB holds a million layers.
constexpr std::int64_t max_manifest_bytes = std::int64_t{256} << 20;

/// Typed access with "<source>: <pointer>: found ...; expected ..." messages.
struct Reader {
  const std::string& source;

  [[noreturn]] void fail(const std::string& ptr, const std::string& what) const {
    throw Error(source + ": " + (ptr.empty() ? std::string("top level") : ptr) + ": " + what);
  }
  [[noreturn]] void fail_type(const std::string& ptr, const json& j, const std::string& expected) const {
    fail(ptr, "found " + trivox::detail::json_describe(j) + "; expected " + expected);
  }
  const json& member(const json& obj, const std::string& ptr, const char* key) const {
    const auto it = obj.find(key);
    if (it == obj.end()) fail(ptr, std::string("no \"") + key + "\"; expected one");
    return *it;
  }
  std::string string(const json& j, const std::string& ptr) const {
    if (!j.is_string()) fail_type(ptr, j, "a string");
    return j.get<std::string>();
  }
  std::string sha(const json& j, const std::string& ptr) const {
    const std::string s = string(j, ptr);
    const bool hex = s.size() == 64 && std::all_of(s.begin(), s.end(), [](char c) {
                       return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f');
                     });
    if (!hex) fail_type(ptr, j, "a SHA-256 digest (64 lowercase hex digits)");
    return s;
  }
  std::int64_t integer(const json& j, const std::string& ptr, std::int64_t lo, std::int64_t hi) const {
    if (!j.is_number_integer() && !j.is_number_unsigned())
      fail_type(ptr, j, "an integer from " + std::to_string(lo) + " to " + std::to_string(hi));
    if (j.is_number_unsigned() && j.get<std::uint64_t>() > static_cast<std::uint64_t>(hi))
      fail_type(ptr, j, "an integer from " + std::to_string(lo) + " to " + std::to_string(hi));
    const auto v = j.get<std::int64_t>();
    if (v < lo || v > hi) fail_type(ptr, j, "an integer from " + std::to_string(lo) + " to " + std::to_string(hi));
    return v;
  }
  const json& array(const json& j, const std::string& ptr, const std::string& of) const {
    if (!j.is_array()) fail_type(ptr, j, "an array of " + of);
    return j;
  }
};

std::string shard_suffix(const Shard& s) {
  return ".shard-" + std::to_string(s.index) + "-of-" + std::to_string(s.count);
}

/// "slice_<digits>.png" whose digits (zero padding allowed) read `index`.
bool is_slice_name(const std::string& name, int index) {
  const std::string head = io::StackConfig{}.prefix, tail = ".png";
  if (name.size() <= head.size() + tail.size() || !name.starts_with(head) || !name.ends_with(tail)) return false;
  const std::string digits = name.substr(head.size(), name.size() - head.size() - tail.size());
  if (digits.size() > 18 || !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return false;
  return std::stoll(digits) == index;
}

/// One layer of manifest `m` (its range, file name and material count) at `p`; after `previous`
/// (in a manifest's ascending list) when given.
ManifestLayer parse_layer(const Reader& r, const json& l, const std::string& p, const Manifest& m,
                          const ManifestLayer* previous = nullptr) {
  if (!l.is_object()) r.fail_type(p, l, "an object {\"index\", \"file\", \"sha256\", \"voxels\", \"failures\"}");
  ManifestLayer ml;
  ml.index = static_cast<int>(r.integer(r.member(l, p, "index"), p + "/index", m.layer_range[0], m.layer_range[1] - 1));
  if (previous && ml.index <= previous->index) r.fail_type(p + "/index", l["index"], "layers in ascending order, each once");
  ml.file = r.string(r.member(l, p, "file"), p + "/file");
  if (!io::plain_file_name(ml.file)) r.fail_type(p + "/file", l["file"], "a file name inside the folder");
  if (!is_slice_name(ml.file, ml.index))
    r.fail_type(p + "/file", l["file"], "slice_" + std::to_string(ml.index) + ".png (zero-padded or not), the name of layer " +
                                            std::to_string(ml.index));
  ml.sha256 = r.sha(r.member(l, p, "sha256"), p + "/sha256");
  const auto& vox = r.array(r.member(l, p, "voxels"), p + "/voxels", "voxel counts");
  if (vox.size() != m.materials.size())
    r.fail_type(p + "/voxels", vox, "one count per material (" + std::to_string(m.materials.size()) + ")");
  for (std::size_t k = 0; k < vox.size(); ++k)
    ml.voxels.push_back(r.integer(vox[k], p + "/voxels/" + std::to_string(k), 0, std::int64_t{1} << 53));
  ml.failures = r.integer(r.member(l, p, "failures"), p + "/failures", 0, std::int64_t{1} << 53);
  return ml;
}

ojson layer_json(const ManifestLayer& l) {
  return {{"index", l.index}, {"file", l.file}, {"sha256", l.sha256}, {"voxels", l.voxels}, {"failures", l.failures}};
}

}  // namespace

// ------------------------------------------------------------------------------------------
// Shards

std::string Shard::manifest_name() const { return part_name("manifest.json"); }

std::string Shard::journal_name() const { return part_name("manifest.journal"); }

std::string Shard::part_name(const std::string& name) const {
  if (count == 1) return name;
  const auto dot = name.rfind('.');
  if (dot == std::string::npos || dot == 0) return name + shard_suffix(*this);
  return name.substr(0, dot) + shard_suffix(*this) + name.substr(dot);
}

std::array<int, 2> Shard::range(int layers, int align) const {
  const long blocks = (static_cast<long>(layers) + align - 1) / align;
  const long b0 = blocks * index / count, b1 = blocks * (index + 1) / count;
  return {static_cast<int>(std::min<long>(layers, b0 * align)), static_cast<int>(std::min<long>(layers, b1 * align))};
}

Shard parse_shard(const std::string& text, const std::string& option) {
  const auto bad = [&]() -> Error {
    return Error(option + " " + text + ": expected K/N with 0 <= K < N <= " + std::to_string(max_shards) +
                 " (shard K counts from 0: 0/3, 1/3, 2/3)");
  };
  const auto slash = text.find('/');
  if (slash == std::string::npos) throw bad();
  auto number = [&](const std::string& s) {
    if (s.empty() || s.size() > 6 || !std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; }))
      throw bad();
    return std::stoi(s);
  };
  const int k = number(text.substr(0, slash)), n = number(text.substr(slash + 1));
  if (n < 1 || n > max_shards || k >= n) throw bad();
  return {k, n};
}

std::optional<Shard> shard_from_environment(std::optional<int> shard_count, const char* (*getenv)(const char*)) {
  const auto get = [&](const char* name) -> const char* {
    if (getenv) return getenv(name);
    return std::getenv(name);
  };
  const auto integer = [&](const char* name, long lo, long hi) -> std::optional<long> {
    const char* v = get(name);
    if (!v) return std::nullopt;
    const std::string s = v;
    const bool digits = !s.empty() && s.size() <= 9 && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
    if (!digits || std::stol(s) < lo || std::stol(s) > hi)
      throw Error(std::string("environment variable ") + name + "=\"" + s + "\": expected an integer from " +
                  std::to_string(lo) + " to " + std::to_string(hi));
    return std::stol(s);
  };
  if (shard_count && (*shard_count < 1 || *shard_count > max_shards))
    throw Error("--shard-count " + std::to_string(*shard_count) + ": expected 1 to " + std::to_string(max_shards));
  if (const auto id = integer("SLURM_ARRAY_TASK_ID", 0, 999999999)) {
    const auto count = integer("SLURM_ARRAY_TASK_COUNT", 1, max_shards);
    const auto min = integer("SLURM_ARRAY_TASK_MIN", 0, 999999999);
    if (!count)
      throw Error("SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not; expected both (a Slurm job "
                  "array), or --shard K/N");
    const long k = *id - min.value_or(0);
    if (k < 0 || k >= *count)
      throw Error("SLURM_ARRAY_TASK_ID " + std::to_string(*id) + " minus SLURM_ARRAY_TASK_MIN " +
                  std::to_string(min.value_or(0)) + " is " + std::to_string(k) + "; expected 0 to " +
                  std::to_string(*count - 1) + " (an array of consecutive task ids; otherwise use --shard K/N)");
    return Shard{static_cast<int>(k), static_cast<int>(*count)};
  }
  if (const auto index = integer("JOB_COMPLETION_INDEX", 0, max_shards - 1)) {
    if (!shard_count)
      throw Error("JOB_COMPLETION_INDEX=" + std::to_string(*index) +
                  " (a Kubernetes Indexed Job) needs the job's completions; expected --shard-count N");
    if (*index >= *shard_count)
      throw Error("JOB_COMPLETION_INDEX " + std::to_string(*index) + ": expected 0 to " +
                  std::to_string(*shard_count - 1) + " for --shard-count " + std::to_string(*shard_count));
    return Shard{static_cast<int>(*index), *shard_count};
  }
  return std::nullopt;
}

// ------------------------------------------------------------------------------------------
// Manifest

bool Manifest::same_job(const Manifest& o) const { return difference(o).empty(); }

std::string Manifest::difference(const Manifest& o) const {
  if (trivox != o.trivox) return "it was written by trivox " + o.trivox + ", this is trivox " + trivox;
  if (model_sha256 != o.model_sha256) return "the model's SHA-256 differs (" + o.model_file + " then, " + model_file + " now)";
  for (const auto& [k, v] : options) {
    const auto it = o.options.find(k);
    if (it == o.options.end()) return "option " + k + " was not set then";
    if (it->second != v) return "option " + k + " was " + it->second + ", now " + v;
  }
  for (const auto& [k, v] : o.options)
    if (!options.count(k)) return "option " + k + " was " + v + " then, and is not set now";
  if (grid != o.grid) return "the voxel grid differs";
  if (materials != o.materials || colours != o.colours) return "the palette's materials differ";
  return {};
}

const ManifestLayer* Manifest::layer(int k) const {
  const auto it = std::lower_bound(layers.begin(), layers.end(), k, [](const ManifestLayer& l, int v) { return l.index < v; });
  return it != layers.end() && it->index == k ? &*it : nullptr;
}

std::string option_number(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

double whole_if_near(double v) {
  const double r = std::round(v);
  return std::abs(v - r) <= 1e-6 ? r : v;
}

io::StackConfig stack_config_of(const Manifest& m, const std::vector<std::int64_t>& totals) {
  io::StackConfig cfg;
  // The job checked that these are whole (slice_job: voxel_print_numbers); the rounding only
  // drops the binary noise of layer_mm * 1e6 (0.027 mm is 27000.000000000004 nm).
  cfg.dpi_x = whole_if_near(m.dpi_x);
  cfg.dpi_y = whole_if_near(m.dpi_y);
  cfg.slice_thickness_nm = whole_if_near(m.layer_mm * 1e6);
  cfg.width = m.grid[0];
  cfg.height = m.grid[1];
  cfg.slices = m.grid[2];
  const auto option = [&](const char* key, const char* otherwise) {
    const auto it = m.options.find(key);
    return it != m.options.end() ? it->second : std::string(otherwise);
  };
  cfg.digits = std::stoi(option("png.digits", "0"));
  cfg.background = io::stack_background(option("png.background", "transparent"));
  cfg.max_colors = std::stoi(option("png.channels", "6"));
  for (std::size_t i = 0; i < m.materials.size() && i < totals.size(); ++i)
    if (totals[i] > 0)
      cfg.materials.push_back({m.materials[i], i < m.colours.size() ? m.colours[i] : std::array<std::uint8_t, 4>{}, totals[i]});
  return cfg;
}

std::string manifest_json(const Manifest& m) {
  ojson j;
  j["trivox_manifest"] = manifest_version;
  j["trivox"] = m.trivox;
  j["model"] = {{"file", m.model_file}, {"sha256", m.model_sha256}};
  ojson opts = ojson::object();
  for (const auto& [k, v] : m.options) opts[k] = v;
  j["options"] = opts;
  j["grid"] = m.grid;
  j["print"] = {{"dpi", {m.dpi_x, m.dpi_y}}, {"layer_mm", m.layer_mm}};
  ojson mats = ojson::array();
  for (std::size_t i = 0; i < m.materials.size(); ++i)
    mats.push_back({{"name", m.materials[i]}, {"rgba", i < m.colours.size() ? m.colours[i] : std::array<std::uint8_t, 4>{}}});
  j["materials"] = mats;
  j["shard"] = {{"index", m.shard.index}, {"count", m.shard.count}};
  j["layer_range"] = m.layer_range;
  j["complete"] = m.complete;
  ojson files = ojson::array();
  for (const auto& f : m.files) files.push_back({{"role", f.role}, {"file", f.file}, {"sha256", f.sha256}});
  j["files"] = files;
  ojson layers = ojson::array();
  for (const auto& l : m.layers) layers.push_back(layer_json(l));
  j["layers"] = layers;
  std::string text = j.dump(2);
  text += '\n';
  return text;
}

Manifest parse_manifest(std::string_view text, const std::string& source) {
  const json root = trivox::detail::parse_json_text(text, source);
  const Reader r{source};
  if (!root.is_object()) r.fail_type("", root, "an object {\"trivox_manifest\": 1, ...}");
  const auto& ver = r.member(root, "", "trivox_manifest");
  if (r.integer(ver, "/trivox_manifest", 0, 1000000) != manifest_version)
    r.fail_type("/trivox_manifest", ver, "1 (a newer trivox wrote this file?)");
  Manifest m;
  m.trivox = r.string(r.member(root, "", "trivox"), "/trivox");
  const auto& model = r.member(root, "", "model");
  if (!model.is_object()) r.fail_type("/model", model, "an object {\"file\", \"sha256\"}");
  m.model_file = r.string(r.member(model, "/model", "file"), "/model/file");
  m.model_sha256 = r.sha(r.member(model, "/model", "sha256"), "/model/sha256");
  const auto& opts = r.member(root, "", "options");
  if (!opts.is_object()) r.fail_type("/options", opts, "an object of strings");
  for (const auto& [k, v] : opts.items()) m.options[k] = r.string(v, "/options/" + k);
  if (m.options.count("png") && m.options.at("png") == "yes") {
    // What trivox wrote before these options were recorded: zero-padded names of 5 digits,
    // transparent void, MaxNumberOfColors 6.
    m.options.try_emplace("png.digits", "5");
    m.options.try_emplace("png.background", "transparent");
    m.options.try_emplace("png.channels", "6");
    const std::string& d = m.options.at("png.digits");
    if (d.size() != 1 || d[0] < '0' || d[0] > '9') r.fail_type("/options/png.digits", opts.at("png.digits"), "a digit count 0..9");
    const std::string& b = m.options.at("png.background");
    if (b != "transparent" && b != "black") r.fail_type("/options/png.background", opts.at("png.background"), "\"transparent\" or \"black\"");
    const std::string& c = m.options.at("png.channels");
    if (c.empty() || c.size() > 3 || !std::all_of(c.begin(), c.end(), [](char ch) { return ch >= '0' && ch <= '9'; }) || std::stoi(c) < 1)
      r.fail_type("/options/png.channels", opts.at("png.channels"), "a material count 1..999");
  }
  const auto& grid = r.array(r.member(root, "", "grid"), "/grid", "3 voxel counts");
  if (grid.size() != 3) r.fail_type("/grid", grid, "an array of 3 voxel counts");
  for (std::size_t d = 0; d < 3; ++d)
    m.grid[d] = static_cast<int>(r.integer(grid[d], "/grid/" + std::to_string(d), 1, 2147483647));
  const auto& print = r.member(root, "", "print");
  if (!print.is_object()) r.fail_type("/print", print, "an object {\"dpi\": [x, y], \"layer_mm\"}");
  const auto& dpi = r.array(r.member(print, "/print", "dpi"), "/print/dpi", "2 numbers");
  if (dpi.size() != 2 || !dpi[0].is_number() || !dpi[1].is_number()) r.fail_type("/print/dpi", dpi, "an array of 2 numbers");
  m.dpi_x = dpi[0].get<double>();
  m.dpi_y = dpi[1].get<double>();
  const auto& layer = r.member(print, "/print", "layer_mm");
  if (!layer.is_number()) r.fail_type("/print/layer_mm", layer, "a number");
  m.layer_mm = layer.get<double>();
  const auto& mats = r.array(r.member(root, "", "materials"), "/materials", "materials");
  for (std::size_t i = 0; i < mats.size(); ++i) {
    const std::string p = "/materials/" + std::to_string(i);
    if (!mats[i].is_object()) r.fail_type(p, mats[i], "an object {\"name\", \"rgba\"}");
    m.materials.push_back(r.string(r.member(mats[i], p, "name"), p + "/name"));
    const auto& c = r.array(r.member(mats[i], p, "rgba"), p + "/rgba", "4 integers 0..255");
    if (c.size() != 4) r.fail_type(p + "/rgba", c, "an array of 4 integers 0..255");
    std::array<std::uint8_t, 4> rgba{};
    for (std::size_t k = 0; k < 4; ++k)
      rgba[k] = static_cast<std::uint8_t>(r.integer(c[k], p + "/rgba/" + std::to_string(k), 0, 255));
    m.colours.push_back(rgba);
  }
  const auto& shard = r.member(root, "", "shard");
  if (!shard.is_object()) r.fail_type("/shard", shard, "an object {\"index\", \"count\"}");
  m.shard.count = static_cast<int>(r.integer(r.member(shard, "/shard", "count"), "/shard/count", 1, max_shards));
  m.shard.index = static_cast<int>(r.integer(r.member(shard, "/shard", "index"), "/shard/index", 0, m.shard.count - 1));
  const auto& range = r.array(r.member(root, "", "layer_range"), "/layer_range", "2 layer indices");
  if (range.size() != 2) r.fail_type("/layer_range", range, "an array of 2 layer indices [first, end)");
  m.layer_range[0] = static_cast<int>(r.integer(range[0], "/layer_range/0", 0, m.grid[2]));
  m.layer_range[1] = static_cast<int>(r.integer(range[1], "/layer_range/1", m.layer_range[0], m.grid[2]));
  const auto& complete = r.member(root, "", "complete");
  if (!complete.is_boolean()) r.fail_type("/complete", complete, "true or false");
  m.complete = complete.get<bool>();
  const auto& files = r.array(r.member(root, "", "files"), "/files", "files");
  for (std::size_t i = 0; i < files.size(); ++i) {
    const std::string p = "/files/" + std::to_string(i);
    if (!files[i].is_object()) r.fail_type(p, files[i], "an object {\"role\", \"file\", \"sha256\"}");
    ManifestFile f{r.string(r.member(files[i], p, "role"), p + "/role"), r.string(r.member(files[i], p, "file"), p + "/file"),
                   r.sha(r.member(files[i], p, "sha256"), p + "/sha256")};
    if (f.role != "config" && f.role != "vdb" && f.role != "zip" && f.role != "mesh")
      r.fail_type(p + "/role", files[i]["role"], "\"config\", \"vdb\", \"zip\" or \"mesh\"");
    for (const ManifestFile& g : m.files)
      if (g.role == f.role) r.fail_type(p + "/role", files[i]["role"], "each role once");
    // The names are turned into paths (resume, --force, merge): each must be the one trivox
    // writes for its role, a plain name inside the folder (the zip: beside it).
    const json& name = files[i]["file"];
    if (f.role == "zip") {
      const std::string base = f.file.starts_with("../") ? f.file.substr(3) : std::string();
      if (!io::plain_file_name(base) || !base.ends_with(".gcvf") || base.size() <= 5)
        r.fail_type(p + "/file", name, "\"../<folder>.gcvf\", the archive beside the folder");
    } else if (!io::plain_file_name(f.file)) {
      r.fail_type(p + "/file", name, "a file name inside the folder");
    } else if (f.role == "config" && f.file != "ConfigFile.xml") {
      r.fail_type(p + "/file", name, "\"ConfigFile.xml\" for role config");
    } else if (f.role == "mesh" && f.file != archive_mesh_name) {
      r.fail_type(p + "/file", name, std::string("\"") + archive_mesh_name + "\" for role mesh");
    } else if (f.role == "vdb") {
      const std::string tail = (m.shard.count > 1 ? shard_suffix(m.shard) : std::string()) + ".vdb";
      if (f.file.size() <= tail.size() || !f.file.ends_with(tail))
        r.fail_type(p + "/file", name, "a VDB named <model>" + tail + " for role vdb");
    }
    m.files.push_back(std::move(f));
  }
  const auto& layers = r.array(r.member(root, "", "layers"), "/layers", "layers");
  for (std::size_t i = 0; i < layers.size(); ++i) {
    ManifestLayer ml = parse_layer(r, layers[i], "/layers/" + std::to_string(i), m, m.layers.empty() ? nullptr : &m.layers.back());
    m.layers.push_back(std::move(ml));
  }
  return m;
}

std::string journal_name_of(const std::string& manifest_name) {
  const std::string stem = manifest_name.ends_with(".json") ? manifest_name.substr(0, manifest_name.size() - 5) : manifest_name;
  return stem + ".journal";
}

std::string journal_header(std::string_view manifest_text) {
  ojson j;
  j["trivox_journal"] = journal_version;
  j["manifest_sha256"] = io::sha256_hex(manifest_text);
  return j.dump() + '\n';
}

std::string journal_line(const ManifestLayer& layer) { return layer_json(layer).dump() + '\n'; }

std::size_t apply_journal(Manifest& m, std::string_view manifest_text, std::string_view journal_text) {
  if (m.complete) return 0;
  const std::string source = "journal";
  const Reader r{source};
  std::map<int, ManifestLayer> added;
  bool header = false;
  // Only whole lines: a last line without its newline was cut short.
  for (std::size_t at = 0, end; (end = journal_text.find('\n', at)) != std::string_view::npos; at = end + 1) {
    const std::string_view line = journal_text.substr(at, end - at);
    json j;
    try {
      j = json::parse(line);
    } catch (const json::exception&) {
      break;
    }
    if (!header) {
      const auto v = j.is_object() ? j.find("trivox_journal") : j.end();
      const auto d = j.is_object() ? j.find("manifest_sha256") : j.end();
      if (v == j.end() || d == j.end() || *v != journal_version || !d->is_string() ||
          d->get<std::string>() != io::sha256_hex(manifest_text))
        return 0;
      header = true;
      continue;
    }
    try {
      ManifestLayer l = parse_layer(r, j, "", m);
      added[l.index] = std::move(l);
    } catch (const Error&) {
      break;
    }
  }
  const std::size_t from_journal = added.size();
  if (from_journal == 0) return 0;
  for (ManifestLayer& l : m.layers) added.try_emplace(l.index, std::move(l));
  m.layers.clear();
  m.layers.reserve(added.size());
  for (auto& [k, l] : added) m.layers.push_back(std::move(l));
  return from_journal;
}

std::optional<Manifest> read_manifest(const std::filesystem::path& dir, const std::string& name) {
  const auto path = dir / name;
  const std::optional<std::string> text = io::read_regular_file(path, max_manifest_bytes);
  if (!text) return std::nullopt;
  Manifest m = parse_manifest(*text, path.string());
  if (!m.complete) {
    // A journal that cannot be read (a link, a folder, too large) adds nothing: its layers are
    // redone.
    std::optional<std::string> journal;
    try {
      journal = io::read_regular_file(dir / journal_name_of(name), max_manifest_bytes);
    } catch (const Error&) {
    }
    if (journal) apply_journal(m, *text, *journal);
  }
  return m;
}

std::string vdb_file_name(const Manifest& m) {
  std::string stem = std::filesystem::path(m.model_file).stem().string();
  if (stem.empty() || !io::plain_file_name(stem + ".vdb")) stem = "model";
  return stem + ".vdb";
}

std::string zip_entry_name(const std::filesystem::path& dir) { return "../" + io::gcvf_path(dir).filename().string(); }

}  // namespace trivox::job
