/// @file trivox/job/slice_job.hpp
/// @brief The print job: sample a V-model on a printer's voxel grid, map each voxel's properties
/// to one printable material, and write a GrabCAD Voxel Print PNG stack.
///
/// A TBB pipeline with a bounded number of layers in flight: layers are sampled in parallel band
/// by band (slice::LayerSampler), mapped to material fractions (slice::MaterialMapper), dithered
/// (slice::LayerDitherer) and painted in palette colours, the three in one pass per row
/// (LayerDitherer::dither_paint), and encoded to PNG in memory; on the colour path up to 8 layers
/// are dithered together (slice::LayerGroupDitherer) into material indices that the encoder
/// paints (encode_png_indexed); an in-order
/// stage writes each slice to a temporary name and renames it. ConfigFile.xml is written last,
/// after a sync, so an interrupted job never looks complete. The manifest (manifest.hpp) is
/// written at the start and the end, the layers finished in between appended to its journal
/// every few seconds after a sync; it lets a killed job resume (`resume`: listed layers
/// whose SHA-256 still matches are kept) and a job run as shards (`shard`: a range of whole
/// 8-layer blocks, merged by merge_job). Memory: per worker one layer of RGBA pixels
/// (width x height x 4 bytes), or on the grouped path 8 layers of indices (8 bytes per pixel,
/// grouping only where those fit in 1 GiB over all workers and within max_memory_bytes), plus
/// one band of samples per layer and the encoded layers in flight; it does not grow with the
/// layer count (SliceJobEstimate::memory_bytes has the model).
/// Output is byte-identical for any thread count (every layer depends on its own inputs only).
/// Masalha, Cirillo & Elber 2021, Sec. 8 (slicing for VoxelPrint).
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "trivox/job/manifest.hpp"
#include "trivox/slice/grid.hpp"
#include "trivox/slice/sampler.hpp"
#include "trivox/vmodel/vmodel.hpp"

namespace trivox::job {

struct SliceJobOptions {
  slice::PrintProfile profile = {};            ///< resolution and tray
  std::filesystem::path out_dir;               ///< the slice folder (created if absent)
  std::string model_name = "model";            ///< for messages and the zip name
  std::optional<std::filesystem::path> palette;  ///< palette file; the default palette when empty
  std::string dither = "fs";                   ///< fs, stochastic or none
  bool force = false;                          ///< write into a non-empty folder, exceed the limits
  /// Also pack the folder as <out_dir>.gcvf, with the model's boundary mesh as Mesh.stl
  /// (job/archive_mesh.hpp; written into the folder by the whole job or shard 0).
  bool zip = false;
  /// Zero padding of the slice numbers in file names: 0 (the default) names them as the public
  /// Voxel Print writers do, `slice_0.png`, `slice_1.png`; 5 gives `slice_00000.png`. 0..9.
  int digits = 0;
  /// The void colour (io::stack_background): "transparent" (0 0 0 0) or "black" (0 0 0 255);
  /// ConfigFile.xml declares it as BackGroundMaterialRGBA. With "black", a palette material
  /// coloured 0 0 0 255 is refused.
  std::string background = "transparent";
  /// Refuse grids of more voxels, or more layers (and so files). `force` does not lift these:
  /// raise them (`--max-voxels`, `--max-layers`).
  std::int64_t max_voxels = 100'000'000'000;
  std::int64_t max_layers = 100'000;
  /// The memory the job may use (`--max-memory`): grouped dithering only where it fits; a job
  /// whose estimate (SliceJobEstimate::memory_bytes) exceeds it even ungrouped is refused.
  std::int64_t max_memory_bytes = std::int64_t{2} << 30;
  /// Check everything, time a few layers and report the estimate (SliceJobSummary::estimate)
  /// without creating the folder or writing any file.
  bool dry_run = false;
  int band_rows = 64;                          ///< rows sampled and dithered at a time
  slice::SamplerOptions sampler;               ///< sampling options (the Shepard blend, --blend)
  /// slice::model_bounds(model), when the caller has it already (a job that also writes a VDB):
  /// saves computing it again (0.4 s on the filleted teapot). Empty: computed here.
  std::optional<std::array<slice::Vec3, 2>> model_box;

  // The manifest (manifest.hpp): what identifies the job, resuming, sharding.
  std::string model_file;                      ///< the model file's name, as given
  std::string model_sha256;                    ///< of the model file's bytes ("" : not known)
  /// Options of other outputs of the same job (the VDB's, say): part of the job's identity, so
  /// that resuming with other values is refused.
  std::map<std::string, std::string> extra_options;
  bool resume = false;                         ///< keep the layers the manifest lists and that verify
  Shard shard;                                 ///< slice only this shard's layers ({0, 1}: all)
  /// Whether this call finishes the job: false when another output (the VDB) follows and will
  /// call finish_manifest; until then the manifest says complete: false.
  bool last_output = true;
  double manifest_interval_s = 2.0;            ///< rewrite the manifest at most this often
};

/// What a job will cost, estimated before it starts (`--dry-run` prints it). The time and the
/// output size extrapolate from 8 layers evenly spread over the job's range, sliced, dithered
/// and encoded in memory; the memory adds to what the process holds already (the libraries,
/// the model and its locator, read from /proc/self/statm) 32 MiB for the threads and the
/// encoder, each worker's buffers and the encoded layers in flight (half a byte per pixel).
struct SliceJobEstimate {
  int layers = 0;                   ///< layers to write (this shard's, less those kept)
  int files = 0;                    ///< files written: slices, ConfigFile.xml, the manifest
  std::int64_t voxels = 0;          ///< voxels of those layers
  int threads = 0;                  ///< worker threads
  bool grouped = false;             ///< layers dithered 8 at a time (within max_memory_bytes)
  double memory_bytes = 0.0;        ///< peak resident memory
  double base_bytes = 0.0;          ///< of it, what the process held before the job
  double seconds = 0.0;             ///< wall time of the layers (setup, sync and manifest not included)
  double output_bytes = 0.0;        ///< the slices' size on disk
  int timed_layers = 0;             ///< layers the figures extrapolate from
  double seconds_per_layer = 0.0;   ///< CPU time of one layer (mean over the timed layers)
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
  /// The archive's boundary mesh (job/archive_mesh.hpp), written with `zip` by a whole job and
  /// shard 0 (empty when not, or when the model could not be meshed), its triangles (0 when
  /// kept from a resumed run), and why there is none when meshing failed (a warning: the
  /// archive is written without it).
  std::filesystem::path mesh_file;
  std::int64_t mesh_triangles = 0;
  std::string mesh_warning;
  /// Thread-seconds (CPU time of the worker threads) spent per stage, summed over workers: sample (locate + evaluate), map
  /// (properties to fractions), dither, paint (material indices to RGBA and counts), encode (PNG
  /// and its SHA-256). Map, dither and paint run as one pass per row
  /// (slice::LayerDitherer::dither_paint), timed together under dither; map and paint stay 0.
  /// Writing is the remainder. For benchmarks and `--json`; not part of any output file.
  std::array<double, 5> stage_seconds{};
  /// Wall-clock seconds of the layers' pipeline alone: `seconds` less the setup before it and the
  /// final sync, ConfigFile.xml and manifest after it (a sync's time varies with the disk).
  double pipeline_seconds = 0.0;
  int layers_kept = 0;                   ///< layers a resumed job found done and verified
  std::array<int, 2> layer_range{};      ///< the layers this job (shard) covers, [first, end)
  Shard shard;
  SliceJobEstimate estimate;             ///< made before the layers (the whole result of a dry run)
  bool dry_run = false;                  ///< nothing was written
};

/// Names of SliceJobSummary::stage_seconds, in order.
inline constexpr std::array<const char*, 5> slice_stage_names{"sample", "map", "dither", "paint", "encode"};

/// Progress reports: layers done of total, voxels done, seconds since the start.
using SliceProgress = std::function<void(int layers_done, int layers_total, std::int64_t voxels_done, double seconds)>;

/// The grid the job would use for `model` (for size checks and `--dry-run`-like reports).
/// @throws Error (bad_input) for an empty model or a degenerate box
slice::VoxelGrid slice_grid(const vmodel::VModel& model, const slice::PrintProfile& profile);

/// The output folder of a job with identity `id` (manifest.hpp), created if absent. A whole job
/// without `resume` wants it new or empty (or `force`); shards share one folder with their
/// siblings; any manifest in it must be of the same job (or `force`, which starts over).
/// `force` without `resume` removes only what a readable trivox manifest there lists with its
/// recorded SHA-256 and trivox's own names (docs/jobs.md, "Overwriting"); in a folder without
/// one it removes nothing. With `force`, a manifest that does not parse (or is a link) is moved
/// aside to `NAME.damaged-<n>`; `force` and `resume` remove this job's (shard's) stale
/// temporaries. What it moved or kept is said on stderr ("trivox: note: ..."). Cost: a listing
/// of the folder, a parse of each manifest, a SHA-256 of each listed VDB it may remove.
/// @return this job's (shard's) manifest when resuming and there is one
/// @throws Error (bad_input) naming the folder and the reason, among them a manifest that does
///         not parse without `force` (its message says that --force moves it aside)
std::optional<Manifest> prepare_job_folder(const std::filesystem::path& dir, const Manifest& id, bool force, bool resume);

/// Marks the manifest of the job in `dir` (shard `shard`) complete, adding `files` (replacing
/// entries of the same role): the last step of a job whose outputs were written by several calls.
/// @throws Error (bad_input) when the manifest is missing or malformed; (failed) when writing fails
void finish_manifest(const std::filesystem::path& dir, const Shard& shard, const std::vector<ManifestFile>& files);

/// Runs the job. @throws Error (bad_input) for bad options (among them a resolution or layer
/// that is not a whole number of dots per inch or nanometres, which ConfigFile.xml cannot hold,
/// and a palette of more materials than the printer's channels), an unusable output folder, a job
/// larger than the tray (unless force), of more than max_voxels voxels or max_layers layers, or
/// whose estimated memory exceeds max_memory_bytes, a malformed palette; (failed) when the PNG
/// module cannot be loaded (checked before the folder is made) or writing fails midway.
SliceJobSummary run_slice_job(const vmodel::VModel& model, const SliceJobOptions& options,
                              const SliceProgress& progress = {});

}  // namespace trivox::job
