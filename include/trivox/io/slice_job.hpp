/// @file trivox/io/slice_job.hpp
/// @brief The print job: sample a V-model on a printer's voxel grid, map each voxel's properties
/// to one printable material, and write a GrabCAD Voxel Print PNG stack.
///
/// A TBB pipeline with a bounded number of layers in flight: layers are sampled in parallel band
/// by band (slice::LayerSampler), mapped to material fractions (slice::MaterialMapper), dithered
/// (slice::LayerDitherer), painted in palette colours and encoded to PNG in memory; an in-order
/// stage writes each slice to a temporary name and renames it. ConfigFile.xml is written last,
/// so an interrupted job never looks complete. Memory: per worker one layer of RGBA pixels
/// (width x height x 4 bytes) plus one band of samples; it does not grow with the layer count.
/// Output is byte-identical for any thread count (every layer depends on its own inputs only).
/// Masalha, Cirillo & Elber 2021, Sec. 8 (slicing for VoxelPrint).
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "trivox/slice/grid.hpp"
#include "trivox/vmodel/vmodel.hpp"

namespace trivox::io {

struct SliceJobOptions {
  slice::PrintProfile profile = {};            ///< resolution and tray
  std::filesystem::path out_dir;               ///< the slice folder (created if absent)
  std::string model_name = "model";            ///< for messages and the zip name
  std::optional<std::filesystem::path> palette;  ///< palette file; the default palette when empty
  std::string dither = "fs";                   ///< fs, stochastic or none
  bool force = false;                          ///< write into a non-empty folder, exceed the limits
  bool zip = false;                            ///< also pack the folder as <out_dir>.gcvf
  std::int64_t max_voxels = 100'000'000'000;   ///< refuse larger grids unless force
  int band_rows = 64;                          ///< rows sampled and dithered at a time
};

/// What a job did, for the summary.
struct SliceJobSummary {
  slice::VoxelGrid grid;
  double seconds = 0.0;
  std::int64_t voxels = 0;               ///< grid voxels visited
  std::int64_t filled = 0;               ///< voxels given a material
  std::int64_t inversion_failures = 0;
  std::vector<std::string> materials;    ///< palette names
  std::vector<std::array<std::uint8_t, 4>> colours;
  std::vector<std::int64_t> material_voxels;
  double voxel_volume_mm3 = 0.0;
  std::string mapping;                   ///< how properties drive materials
  std::filesystem::path zip_file;        ///< set when zip was asked for
};

/// Progress reports: layers done of total, voxels done, seconds since the start.
using SliceProgress = std::function<void(int layers_done, int layers_total, std::int64_t voxels_done, double seconds)>;

/// The grid the job would use for `model` (for size checks and `--dry-run`-like reports).
/// @throws Error (bad_input) for an empty model or a degenerate box
slice::VoxelGrid slice_grid(const vmodel::VModel& model, const slice::PrintProfile& profile);

/// Runs the job. @throws Error (bad_input) for bad options, an unusable output folder, a job
/// larger than the tray or max_voxels (unless force), a malformed palette; (failed) when writing
/// fails midway.
SliceJobSummary run_slice_job(const vmodel::VModel& model, const SliceJobOptions& options,
                              const SliceProgress& progress = {});

}  // namespace trivox::io
