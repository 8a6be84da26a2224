// `trivox inspect DIR`: reads a Voxel Print slice folder back (io::inspect_stack): its
// configuration, which slices are missing or corrupt, voxels and volume per material. Exit 1
// when the stack is invalid (a slice missing or corrupt, or a VoxelCount that the pixels
// contradict), after printing the report; exit 2 when the folder or its ConfigFile.xml is unusable.
#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "common.hpp"
#include "trivox/error.hpp"
#include "trivox/io/slice_stack.hpp"

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
            {"background", c.background}}},
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

}  // namespace

void add_inspect(CLI::App& app, Common& common) {
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "inspect", "Read a slice folder back: configuration, missing or corrupt slices, voxels and volume per material");
  sub->add_option("DIR", opt->path, "Slice folder (holding ConfigFile.xml and the PNG slices)")->required();
  sub->add_flag("--json", common.json, "Print one JSON object instead of the summary");
  sub->callback([opt, &common] {
    std::error_code ec;
    if (std::filesystem::is_regular_file(opt->path, ec))
      throw Error(opt->path + ": is a file; expected a slice folder holding ConfigFile.xml (unzip a .gcvf first)");
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
