#include "trivox/slice/grid.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "trivox/error.hpp"

namespace trivox::slice {

namespace {
/// Stratasys' PolyJet printers of the J series that Voxel Print serves: the same resolution and
/// tray; the J750 holds 6 model materials at once, the J850 7 (their product specifications).
PrintProfile polyjet(std::string name, int channels) {
  PrintProfile p;
  p.channels = channels;
  p.name = std::move(name);
  p.dpi_x = 600.0;
  p.dpi_y = 300.0;
  p.layer_mm = 0.027;
  p.tray_mm = {490.0, 390.0, 200.0};
  return p;
}
}  // namespace

std::vector<std::string> printer_presets() { return {"j750", "j850"}; }

PrintProfile printer_preset(std::string_view name) {
  for (const auto& known : printer_presets())
    if (name == known) return polyjet(known, known == "j850" ? 7 : 6);
  std::string list;
  for (const auto& known : printer_presets()) list += (list.empty() ? "" : ", ") + known;
  throw Error("--printer " + std::string(name) + ": unknown printer; expected one of " + list);
}

VoxelGrid VoxelGrid::covering(const std::array<double, 3>& lo, const std::array<double, 3>& hi,
                              const std::array<double, 3>& pitch) {
  VoxelGrid g;
  g.origin = lo;
  g.pitch = pitch;
  static constexpr const char* axis = "xyz";
  for (int d = 0; d < 3; ++d) {
    const auto dd = static_cast<std::size_t>(d);
    if (!(std::isfinite(pitch[dd]) && pitch[dd] > 0.0))
      throw Error(std::string("voxel pitch along ") + axis[d] + " is " + std::to_string(pitch[dd]) +
                  " mm; expected a positive finite size");
    if (!(std::isfinite(lo[dd]) && std::isfinite(hi[dd]) && hi[dd] >= lo[dd]))
      throw Error(std::string("bounding box along ") + axis[d] + " is [" + std::to_string(lo[dd]) + ", " +
                  std::to_string(hi[dd]) + "]; expected a finite non-empty box");
    const double n = std::max(1.0, std::ceil((hi[dd] - lo[dd]) / pitch[dd]));
    if (n > std::numeric_limits<int>::max())
      throw Error(std::string("grid of ") + std::to_string(n) + " voxels along " + axis[d] +
                  "; expected at most 2147483647");
    g.count[dd] = static_cast<int>(n);
  }
  return g;
}

void check_solid_box(const std::array<double, 3>& lo, const std::array<double, 3>& hi, const std::string& name) {
  static constexpr const char* axis = "xyz";
  const auto g = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return std::string(buf);
  };
  for (std::size_t d = 0; d < 3; ++d) {
    const double extent = hi[d] - lo[d];
    if (!(std::isfinite(lo[d]) && std::isfinite(hi[d]) && extent > 0.0))
      throw Error(name + ": the model's box is " + g(extent) + " mm along " + axis[d] + " (from " + g(lo[d]) + " to " +
                  g(hi[d]) +
                  "); expected a solid with extent along x, y and z (a flat or collapsed cell has no volume to print)");
  }
}

}  // namespace trivox::slice
