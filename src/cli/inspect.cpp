// `trivox inspect DIR`: reads a Voxel Print slice folder back (io::inspect_stack): its
// configuration, which slices are missing or corrupt, voxels and volume per material. Exit 1
// when the stack is invalid (a slice missing or corrupt, or a VoxelCount that the pixels
// contradict), after printing the report; exit 2 when the folder or its ConfigFile.xml is unusable.
// `trivox inspect FILE.vdb` (a .vdb name, or any file starting with OpenVDB's magic number):
// the grids of an OpenVDB file (io::inspect_vdb); exit 2 when it is missing, not a VDB file or
// corrupt.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>

#include "common.hpp"
#include "trivox/error.hpp"
#include "trivox/io/stack_config.hpp"
#include "trivox/io/stack_inspect.hpp"
#include "trivox/io/vdb_inspect.hpp"

namespace trivox::cli {

namespace {

struct Options {
  std::string path;
};

nlohmann::ordered_json to_json(const io::StackReport& r, const std::string& path) {
  const io::StackConfig& c = r.config;
  nlohmann::ordered_json materials = nlohmann::ordered_json::array();
  for (std::size_t m = 0; m < c.materials.size(); ++m)
    materials.push_back({{"name", c.materials[m].name},
                         {"rgba", c.materials[m].rgba},
                         {"voxels", r.voxels_per_material[m]},
                         {"recorded_voxels", c.materials[m].voxel_count},
                         {"volume_mm3", r.volume_per_material_mm3[m]}});
  nlohmann::ordered_json problems = nlohmann::ordered_json::array();
  for (const auto& p : r.problems) problems.push_back({{"index", p.index}, {"file", p.file}, {"reason", p.reason}});
  nlohmann::ordered_json mismatch = nlohmann::ordered_json::array();
  for (int m : r.count_mismatch) mismatch.push_back(c.materials[static_cast<std::size_t>(m)].name);
  return {{"path", path},
          {"valid", r.valid()},
          {"config",
           {{"version", c.version},
            {"dpi", {c.dpi_x, c.dpi_y}},
            {"slice_thickness_nm", c.slice_thickness_nm},
            {"width", c.width},
            {"height", c.height},
            {"start_index", c.start_index},
            {"slices", c.slices},
            {"prefix", c.prefix},
            {"digits", c.digits},
            {"background", c.background},
            {"max_colors", c.max_colors}}},
          {"voxel_size_mm", {25.4 / c.dpi_x, 25.4 / c.dpi_y, c.slice_thickness_nm * 1e-6}},
          {"voxel_volume_mm3", r.voxel_volume_mm3},
          {"size_mm", {c.width * 25.4 / c.dpi_x, c.height * 25.4 / c.dpi_y, c.slices * c.slice_thickness_nm * 1e-6}},
          {"present", r.present},
          {"missing", r.missing},
          {"corrupt", r.corrupt},
          {"problems", problems},
          {"extra", r.extra},
          {"materials", materials},
          {"voxels", r.voxels},
          {"volume_mm3", r.volume_mm3},
          {"void_voxels", r.void_voxels},
          {"foreign_pixels", r.foreign_pixels},
          {"count_mismatch", mismatch}};
}

std::string list(const std::vector<int>& v, std::size_t most = 20) {
  std::string s;
  for (std::size_t i = 0; i < v.size() && i < most; ++i) s += (i ? ", " : "") + std::to_string(v[i]);
  if (v.size() > most) s += ", ... (" + std::to_string(v.size()) + " in all)";
  return s;
}

void print_human(const io::StackReport& r, const std::string& path) {
  const io::StackConfig& c = r.config;
  std::printf("%s: Voxel Print stack (ConfigFile.xml version %d)\n", path.c_str(), c.version);
  std::printf("resolution: %s x %s dpi, layers %s nm; voxel %s x %s x %s mm = %s mm^3\n", fmt(c.dpi_x).c_str(),
              fmt(c.dpi_y).c_str(), fmt(c.slice_thickness_nm).c_str(), fmt(25.4 / c.dpi_x, 6).c_str(),
              fmt(25.4 / c.dpi_y, 6).c_str(), fmt(c.slice_thickness_nm * 1e-6, 6).c_str(), fmt(r.voxel_volume_mm3, 6).c_str());
  std::printf("slices: %d of %d x %d px (%s x %s x %s mm), %s .. %s\n", c.slices, c.width, c.height,
              fmt(c.width * 25.4 / c.dpi_x, 6).c_str(), fmt(c.height * 25.4 / c.dpi_y, 6).c_str(),
              fmt(c.slices * c.slice_thickness_nm * 1e-6, 6).c_str(), c.slice_name(0).c_str(),
              c.slice_name(c.slices - 1).c_str());
  std::printf("void: %s (%s); MaxNumberOfColors %d\n", io::stack_background_name(c.background).c_str(),
              (std::to_string(c.background[0]) + " " + std::to_string(c.background[1]) + " " + std::to_string(c.background[2]) + " " + std::to_string(c.background[3])).c_str(), c.max_colors);
  std::printf("present: %d of %d", r.present, c.slices);
  if (!r.missing.empty()) std::printf("; missing %zu: %s", r.missing.size(), list(r.missing).c_str());
  if (!r.corrupt.empty()) std::printf("; corrupt %zu: %s", r.corrupt.size(), list(r.corrupt).c_str());
  std::printf("\n");
  std::printf("\n%-20s %-16s %14s %14s %14s\n", "material", "RGBA", "voxels", "volume mm^3", "recorded");
  for (std::size_t m = 0; m < c.materials.size(); ++m) {
    const auto& mat = c.materials[m];
    const std::string rgba = std::to_string(mat.rgba[0]) + " " + std::to_string(mat.rgba[1]) + " " +
                             std::to_string(mat.rgba[2]) + " " + std::to_string(mat.rgba[3]);
    std::printf("%-20s %-16s %14lld %14s %14lld%s\n", mat.name.c_str(), rgba.c_str(),
                static_cast<long long>(r.voxels_per_material[m]), fmt(r.volume_per_material_mm3[m], 8).c_str(),
                static_cast<long long>(mat.voxel_count),
                std::find(r.count_mismatch.begin(), r.count_mismatch.end(), static_cast<int>(m)) != r.count_mismatch.end()
                    ? "  differs"
                    : "");
  }
  std::printf("%-20s %-16s %14lld %14s\n", "total", "", static_cast<long long>(r.voxels), fmt(r.volume_mm3, 8).c_str());
  std::printf("void voxels: %lld\n", static_cast<long long>(r.void_voxels));
  if (!r.problems.empty()) {
    std::printf("\nproblems:\n");
    std::size_t shown = 0;
    for (const auto& p : r.problems) {
      if (++shown > 50) {
        std::printf("  ... %zu more\n", r.problems.size() - 50);
        break;
      }
      std::printf("  %s: %s\n", p.file.c_str(), p.reason.c_str());
    }
  }
  if (!r.extra.empty())
    std::printf("\nfiles outside the slice range (ignored): %s\n", list(r.extra).c_str());
  std::printf("\n%s\n", r.valid() ? "stack is valid" : "stack is INVALID");
}

// ---- .vdb files ----

nlohmann::ordered_json meta_json(const std::vector<io::VdbMeta>& meta) {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  for (const auto& m : meta) {
    if (m.type == "bool")
      j[m.name] = m.value == "1" || m.value == "true";
    else if (m.numeric && m.type != "float" && m.type != "double")
      j[m.name] = std::stoll(m.value);
    else if (m.numeric && std::isfinite(std::strtod(m.value.c_str(), nullptr)))  // JSON has no NaN: keep the text
      j[m.name] = std::strtod(m.value.c_str(), nullptr);
    else
      j[m.name] = m.value;
  }
  return j;
}

nlohmann::ordered_json values_json(const std::vector<double>& v, int components) {
  if (v.empty()) return nullptr;
  if (components == 1) return v[0];
  return v;
}

nlohmann::ordered_json vdb_json(const io::VdbReport& r) {
  nlohmann::ordered_json grids = nlohmann::ordered_json::array();
  for (const auto& g : r.grids) {
    nlohmann::ordered_json j = {{"name", g.name},
                                {"type", g.type},
                                {"class", g.grid_class},
                                {"voxel_size", g.voxel_size},
                                {"active_voxels", g.active_voxels}};
    if (g.empty) {
      j["index_bounds"] = nullptr;
      j["world_bounds"] = nullptr;
    } else {
      j["index_bounds"] = g.index_bounds;
      j["world_bounds"] = g.world_bounds;
    }
    j["min"] = values_json(g.min, g.components);
    j["max"] = values_json(g.max, g.components);
    j["mean"] = values_json(g.mean, g.components);
    j["metadata"] = meta_json(g.metadata);
    grids.push_back(std::move(j));
  }
  // Volumes in mm^3 whatever the file's unit (a file in metres holds m^3); a file of unknown
  // units is taken as millimetres, as trivox writes by default.
  const double k = std::pow(r.mm_per_unit.value_or(1.0), 3);
  nlohmann::ordered_json materials = nlohmann::ordered_json::array();
  for (const auto& m : r.materials) materials.push_back({{"name", m.name}, {"volume_mm3", m.volume * k}});
  return {{"path", r.path},
          {"kind", "vdb"},
          {"bytes", r.bytes},
          {"format", r.format},
          {"units", r.units.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(r.units)},
          {"metadata", meta_json(r.metadata)},
          {"grids", grids},
          {"volume_mm3", r.volume ? nlohmann::ordered_json(*r.volume * k) : nlohmann::ordered_json(nullptr)},
          {"materials", materials}};
}

std::string values_text(const std::vector<double>& v) {
  if (v.empty()) return "-";
  if (v.size() == 1) return fmt(v[0], 6);
  std::string s = "(";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + fmt(v[i], 4);
  return s + ")";
}

template <class T>
std::string triple(const std::array<T, 3>& v, int digits = 6) {
  std::string s = "(";
  for (std::size_t i = 0; i < 3; ++i) s += (i ? ", " : "") + fmt(static_cast<double>(v[i]), digits);
  return s + ")";
}

std::string bytes_text(std::int64_t b) {
  const char* units[] = {"B", "KB", "MB", "GB", "TB"};
  double v = static_cast<double>(b);
  int u = 0;
  while (v >= 1000.0 && u < 4) v /= 1000.0, ++u;
  return fmt(v, 3) + " " + units[u];
}

void print_vdb(const io::VdbReport& r) {
  std::printf("%s: OpenVDB file (library/format %s), %zu grids, %s\n", r.path.c_str(), r.format.c_str(), r.grids.size(),
              bytes_text(r.bytes).c_str());
  if (!r.metadata.empty()) {
    std::printf("file metadata:\n");
    for (const auto& m : r.metadata) std::printf("  %-20s %s\n", m.name.c_str(), m.value.c_str());
  }
  std::size_t w = 20;
  for (const auto& g : r.grids) w = std::max(w, g.name.size());
  const int wi = static_cast<int>(w);
  std::printf("\n%-*s %-6s %-11s %-10s %13s  %-22s %-22s %s\n", wi, "grid", "type", "class", "voxel", "active voxels", "min",
              "max", "mean");
  for (const auto& g : r.grids) {
    const bool uniform = g.voxel_size[0] == g.voxel_size[1] && g.voxel_size[1] == g.voxel_size[2];
    const std::string voxel = uniform ? fmt(g.voxel_size[0], 6) : triple(g.voxel_size, 4);
    std::printf("%-*s %-6s %-11s %-10s %13lld  %-22s %-22s %s\n", wi, g.name.c_str(), g.type.c_str(),
                g.grid_class.c_str(), voxel.c_str(), static_cast<long long>(g.active_voxels), values_text(g.min).c_str(),
                values_text(g.max).c_str(), values_text(g.mean).c_str());
  }
  const std::string world = "world (voxel boxes" + (r.units.empty() ? std::string() : ", " + r.units) + ")";
  std::printf("\n%-*s %-34s %s\n", wi, "active bounds", "index (voxels, inclusive)", world.c_str());
  for (const auto& g : r.grids) {
    if (g.empty) {
      std::printf("%-*s %s\n", wi, g.name.c_str(), "(no active voxels)");
      continue;
    }
    const std::string index = triple(g.index_bounds[0]) + " - " + triple(g.index_bounds[1]);
    std::printf("%-*s %-34s %s - %s\n", wi, g.name.c_str(), index.c_str(), triple(g.world_bounds[0]).c_str(),
                triple(g.world_bounds[1]).c_str());
  }
  const std::string unit = r.units.empty() ? "units" : r.units;
  if (r.volume) {
    std::printf("\nvolume: %s %s^3 (sum of density x voxel volume)\n", fmt(*r.volume, 10).c_str(), unit.c_str());
    if (!r.materials.empty()) {
      std::printf("\n%-*s %16s\n", wi, "material", (unit + "^3").c_str());
      for (const auto& m : r.materials) std::printf("%-*s %16s\n", wi, m.name.c_str(), fmt(m.volume, 10).c_str());
    }
  } else {
    std::printf("\nvolume: no float grid \"density\"\n");
  }
}

bool vdb_name(const std::filesystem::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".vdb";
}

}  // namespace

void add_inspect(CLI::App& app, Common& common) {
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "inspect", "Read a slice folder or a .vdb file back: configuration or grids, problems, voxels and volume per material");
  sub->add_option("PATH", opt->path, "Slice folder (holding ConfigFile.xml and the PNG slices), or an OpenVDB file (.vdb)")->required();
  sub->add_flag("--json", common.json, "Print one JSON object instead of the summary");
  sub->callback([opt, &common] {
    std::error_code ec;
    const std::filesystem::path path(opt->path);
    if (vdb_name(path) || (std::filesystem::is_regular_file(path, ec) && io::looks_like_vdb(path))) {
      const io::VdbReport r = io::inspect_vdb(path);
      if (common.json)
        print_json(vdb_json(r));
      else
        print_vdb(r);
      return;
    }
    if (std::filesystem::is_regular_file(path, ec))
      throw Error(opt->path + ": is a file; expected a slice folder holding ConfigFile.xml (unzip a .gcvf first) "
                  "or an OpenVDB file (.vdb)");
    const io::StackReport r = io::inspect_stack(opt->path);
    if (common.json)
      print_json(to_json(r, opt->path));
    else
      print_human(r, opt->path);
    std::fflush(stdout);
    if (!r.valid()) {
      std::string why;
      if (!r.missing.empty()) why += std::to_string(r.missing.size()) + " missing";
      if (!r.corrupt.empty()) why += (why.empty() ? "" : ", ") + std::to_string(r.corrupt.size()) + " corrupt";
      if (!r.count_mismatch.empty())
        why += (why.empty() ? "" : ", ") + std::to_string(r.count_mismatch.size()) + " VoxelCount mismatches";
      throw Error(opt->path + ": invalid stack: " + why + "; expected every slice present, readable and as recorded",
                  ErrorKind::failed);
    }
  });
}

}  // namespace trivox::cli
