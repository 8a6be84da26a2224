/// @file trivox/io/vdb_inspect.hpp
/// @brief Reading an OpenVDB file back: what its grids hold (`trivox inspect FILE.vdb`), and a
/// picture of its coloured volume (`trivox render FILE.vdb`).
///
/// inspect_vdb reads every grid (any OpenVDB file, not only trivox's) and reports per grid its
/// name, value type, class, voxel size, active bounds in index and world coordinates, active
/// voxel count, and the range and mean of its active values (per component for vectors); then,
/// when the file has a float grid `density`, the volume sum(density x voxel volume) and per
/// `material.<name>` float grid sum(fraction x density x voxel volume).
/// Cost: one full read of the file (all grids in memory), then one pass over the active voxels.
///
/// render_vdb composites density and colour front to back along parallel rays (orthographic
/// projection): per step of half a voxel, opacity 1 - exp(-density x step / voxel) and the colour
/// at that point (trilinear), lit by a head light through the density gradient, over the
/// background. Cost: width x height rays of at most (box diagonal / half a voxel) steps, each a
/// few trilinear lookups; rays stop once nearly opaque. Parallel over image rows; the picture does
/// not depend on the thread count.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace trivox::io {

/// One metadata entry, its value as text.
struct VdbMeta {
  std::string name;
  std::string type;      ///< OpenVDB's type name: "string", "double", "int32", "vec3s", ...
  std::string value;     ///< the value as OpenVDB prints it (Metadata::str)
  bool numeric = false;  ///< a single number (bool, integer or floating point)
};

/// What one grid holds.
struct VdbGridInfo {
  std::string name;
  std::string type;         ///< value type: "float", "double", "vec3s", "int32", "bool", ...
  std::string grid_class;   ///< "fog volume", "level set", "staggered" or "unknown"
  std::array<double, 3> voxel_size{};  ///< world units (VdbReport::units) per voxel along x, y, z
  std::int64_t active_voxels = 0;
  bool empty = true;                   ///< no active voxels: bounds, range and mean are unset
  std::array<std::array<int, 3>, 2> index_bounds{};      ///< min and max active voxel (inclusive)
  std::array<std::array<double, 3>, 2> world_bounds{};   ///< the box of those voxels' cubes
  int components = 0;                  ///< 1 scalar, 3 vector, 0 values not summarised
  std::vector<double> min, max, mean;  ///< per component, over active voxels
  std::vector<VdbMeta> metadata;       ///< the grid's own metadata (not OpenVDB's file_* statistics)
};

/// What a .vdb file holds.
struct VdbReport {
  std::string path;
  std::int64_t bytes = 0;
  std::string format;                 ///< "<library major>.<minor>/<file format>", e.g. "10.0/224"
  std::vector<VdbMeta> metadata;      ///< file-level metadata
  std::vector<VdbGridInfo> grids;     ///< in file order
  std::optional<double> volume;       ///< sum(density x voxel volume), when a float `density` grid exists
  struct MaterialVolume {
    std::string name;                 ///< the material (grid name without "material.")
    double volume = 0.0;              ///< sum(fraction x density x voxel volume)
  };
  std::vector<MaterialVolume> materials;
  std::string units;                  ///< the file's "units" metadata, or empty: the unit of
                                      ///< world_bounds, voxel_size and volume (trivox: mm or m)
  /// Millimetres per world unit when `units` names one trivox knows ("mm": 1, "m": 1000), so
  /// that volume x mm_per_unit^3 is in mm^3; empty for other or no units.
  std::optional<double> mm_per_unit;
};

/// Reads and summarises a .vdb file.
/// @throws Error (bad_input) "<path>: ...; expected an OpenVDB file" when the file is missing,
///         a folder, not a VDB file, truncated or corrupt
VdbReport inspect_vdb(const std::filesystem::path& path);

/// True when the file starts with OpenVDB's magic number (cheap: reads 8 bytes).
bool looks_like_vdb(const std::filesystem::path& path);

/// How to draw a volume.
struct RenderOptions {
  /// Direction the volume is seen from: "+z" (top: x right, y up), "-z" (bottom: x right, y
  /// down), "+x", "-x", "+y", "-y" (sides, z up), "iso" (from +x, -y, +z; z up).
  std::string view = "iso";
  int width = 0, height = 0;   ///< picture size; 0, 0: the longer side 800 px, aspect of the view
  std::array<std::uint8_t, 4> background{255, 255, 255, 255};  ///< alpha 0: transparent background
  bool force = false;          ///< replace an existing picture
};

/// What render_vdb drew.
struct RenderSummary {
  int width = 0, height = 0;
  std::string view;
  std::string density_grid, color_grid;  ///< grids used (color_grid empty: drawn light grey)
  std::int64_t covered_pixels = 0;       ///< pixels where the volume's opacity exceeds 1%
};

/// Renders `vdb` to the PNG `png` (written atomically).
/// @throws Error (bad_input) as inspect_vdb, for a bad view or size (each side 16..16384), a file
///         without a float grid to draw (`density`, else the first fog volume or float grid), an
///         existing picture without force, or an unwritable path
RenderSummary render_vdb(const std::filesystem::path& vdb, const std::filesystem::path& png,
                         const RenderOptions& options);

}  // namespace trivox::io
