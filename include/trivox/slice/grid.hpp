/// @file trivox/slice/grid.hpp
/// @brief Printer profiles and the voxel grid a model is sampled on.
///
/// Axes and origin (the contract every slice writer and reader follows):
/// - Model units are mm. The grid covers the axis-aligned bounding box of the model's cells
///   (xyz of their Bezier pieces' control points), starting at its minimum corner `origin`.
/// - Voxel (i, j, k) has its centre at origin + ((i + 1/2) px, (j + 1/2) py, (k + 1/2) pz) with
///   pitches px = 25.4 / dpi_x, py = 25.4 / dpi_y (the printer's X is the print-head direction,
///   600 dpi on the J750) and pz = the layer thickness. nx = ceil(extent_x / px) (at least 1),
///   likewise ny, nz: the grid may overhang the box by less than one voxel on the far side.
/// - Layer k is slice image k; image column i is x; image row r holds j = ny - 1 - r, so an image
///   viewed top-down shows the model as seen from +z with +y up.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace trivox::slice {

/// A printer's resolution and build volume.
struct PrintProfile {
  std::string name = "custom";
  double dpi_x = 600.0, dpi_y = 300.0;  ///< pixels per inch along x (image columns) and y (rows)
  double layer_mm = 0.027;              ///< layer thickness
  std::array<double, 3> tray_mm{490.0, 390.0, 200.0};
  /// Model materials the printer holds at once: the most one job may use (ConfigFile.xml's
  /// `MaxNumberOfColors`). 6 on the J750, 7 on the J850 (Stratasys' product specifications).
  int channels = 6;

  double pitch_x() const noexcept { return 25.4 / dpi_x; }
  double pitch_y() const noexcept { return 25.4 / dpi_y; }
  double pitch_z() const noexcept { return layer_mm; }
};

/// Known presets: "j750", "j850" (600 x 300 dpi, 27 um layers, tray 490 x 390 x 200 mm; 6 and
/// 7 model materials at once).
/// @throws Error (bad_input) for an unknown name, listing the known ones
PrintProfile printer_preset(std::string_view name);
/// Names accepted by printer_preset.
std::vector<std::string> printer_presets();

/// The voxel grid of a job (see the file comment for axes and origin).
struct VoxelGrid {
  std::array<double, 3> origin{};  ///< minimum corner of the sampled box, mm
  std::array<double, 3> pitch{};   ///< voxel size along x, y, z, mm
  std::array<int, 3> count{};      ///< nx, ny, nz

  /// Centre of voxel (i, j, k).
  std::array<double, 3> centre(int i, int j, int k) const noexcept {
    return {origin[0] + (i + 0.5) * pitch[0], origin[1] + (j + 0.5) * pitch[1], origin[2] + (k + 0.5) * pitch[2]};
  }
  std::int64_t voxels() const noexcept {
    return static_cast<std::int64_t>(count[0]) * count[1] * count[2];
  }
  std::int64_t voxels_per_layer() const noexcept { return static_cast<std::int64_t>(count[0]) * count[1]; }

  /// The grid of the given pitches over the box [lo, hi].
  /// @throws Error (bad_input) on non-finite or non-positive pitches, an empty box, or more than
  ///         2^31 - 1 voxels along an axis
  static VoxelGrid covering(const std::array<double, 3>& lo, const std::array<double, 3>& hi,
                            const std::array<double, 3>& pitch);
};

/// Refuses a model box without volume: a point, or a box of zero extent along some axis (every
/// cell flat, say), where nothing would print although the job would run.
/// @param lo, hi  the model's bounding box, mm
/// @param name    the model (its file) for the message
/// @throws Error (bad_input) naming the axis and the extent; also for a non-finite box
void check_solid_box(const std::array<double, 3>& lo, const std::array<double, 3>& hi, const std::string& name);

}  // namespace trivox::slice
