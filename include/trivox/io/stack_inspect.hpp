/// @file trivox/io/stack_inspect.hpp
/// @brief Reading a Voxel Print slice stack back (`trivox inspect DIR`): missing and corrupt
/// slices, voxels and volume per material.
///
/// Cost: one decode of every slice, streaming rows: memory per thread is the compressed file plus
/// about 1 MB of rows, whatever the slice size.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>
#include "trivox/io/stack_config.hpp"

namespace trivox::io {

/// One missing or corrupt slice.
struct SliceProblem {
  int index = 0;        ///< the slice's number as in its file name (start_index + position)
  std::string file;     ///< its file name
  std::string reason;   ///< "missing", "truncated or unreadable PNG: ...", "1000 x 20 pixels; expected ...",
                        ///< "37 pixels of foreign colours, first (12, 3) = 255 0 0 255; expected ..."
};

/// What a stack holds (inspect_stack).
struct StackReport {
  StackConfig config;                           ///< from ConfigFile.xml, `digits` from the folder
  int present = 0;                              ///< slices whose file exists
  std::vector<int> missing, corrupt;            ///< slice numbers (as in file names), ascending
  std::vector<SliceProblem> problems;           ///< one per missing or corrupt slice, in order
  std::vector<int> extra;                       ///< `<prefix><n>.png` files outside the range
  std::vector<std::int64_t> voxels_per_material;  ///< counted in readable slices, config.materials order
  std::vector<double> volume_per_material_mm3;  ///< voxels * voxel_volume_mm3
  std::vector<int> count_mismatch;              ///< materials whose VoxelCount differs from the count
                                                ///< (checked only when no slice is missing or corrupt)
  std::int64_t voxels = 0;                      ///< material voxels in all readable slices
  std::int64_t void_voxels = 0;                 ///< void pixels (alpha 0 or the background colour)
  std::int64_t foreign_pixels = 0;              ///< pixels of no palette colour, in all slices
  double voxel_volume_mm3 = 0;                  ///< one voxel
  double volume_mm3 = 0;                        ///< all material voxels

  /// No missing or corrupt slice, and every VoxelCount matches the pixels (only then are the
  /// counts complete; a mismatch alone also makes the stack invalid).
  bool valid() const noexcept { return missing.empty() && corrupt.empty() && count_mismatch.empty(); }
};

/// Reads a stack back: the configuration, then every slice (OpenImageIO, rows streamed, slices
/// in parallel with TBB). A slice is corrupt when it cannot be decoded to the end (truncated,
/// not a PNG), has another size than SliceWidth x SliceHeight, is not 8-bit RGB(A), or holds a
/// pixel that is neither void (alpha 0, or the background colour) nor a material's colour.
/// Voxels are counted per material over readable slices (foreign pixels are not counted).
/// Cost: one decode of every slice; memory per thread: one compressed slice and about 1 MB of rows.
/// @throws trivox::Error (bad_input) only when the folder or its ConfigFile.xml is unusable
///         (read_stack_config); slice problems are reported, never thrown; (failed) when the
///         PNG module cannot be loaded
StackReport inspect_stack(const std::filesystem::path& dir);

}  // namespace trivox::io
