/// @file trivox/job/vdb_job.hpp
/// @brief The OpenVDB output of a print job: sample a V-model on a uniform cubic voxel grid and
/// write `DIR/<name>.vdb` with its density, colour, material fractions and other properties.
///
/// Grids, in file order (docs/vdb.md has the full contract):
/// - `density`: FloatGrid of class fog volume, 0..1: the fraction of a voxel's N^3 sub-samples
///   (`supersample` N, stratified at the centres of the N^3 sub-cubes) that lie inside the model;
///   a voxel is active exactly when its density is above 0.
/// - `color`: Vec3SGrid, 0..1: the model's `r`, `g`, `b` when it has all three (clamped to
///   0..1), otherwise the mix of the palette materials' RGB / 255 weighted by their fractions;
///   `Cd`: a copy of it (Houdini's name for colour). VdbColorSpace::linear (the default): each
///   sRGB colour (a sub-sample's r, g, b; a palette colour) is decoded to linear
///   (io::srgb_to_linear) before the mean and the mix; srgb: the encoded values mixed as they are.
/// - `material.<name>`: one FloatGrid per palette material: its fraction before dithering
///   (slice::MaterialMapper), summing to 1 over the materials in every active voxel.
/// - one FloatGrid per other model property (not r, g, b and not a palette material's name),
///   named like the property, or `property.<name>` when the name is taken by a grid above or is
///   one that Blender or Houdini read with a meaning (density, color, Cd, temperature, heat,
///   flame).
/// Colour, fractions and properties are means over the inside sub-samples. Every grid has the
/// active topology of `density`.
///
/// Voxel (i, j, k) is index coordinate (i, j, k) and has its centre at origin + (i + 1/2,
/// j + 1/2, k + 1/2) * voxel (world units: model mm; with VdbUnits::m every length of the
/// transform and the metadata divided by 1000), origin being the minimum corner of the
/// model's bounding box (slice::model_bounds), like the slice grid (slice/grid.hpp).
///
/// How: the model is sampled by slice::LayerSampler on a fine grid of pitch voxel / N (its voxel
/// centres are the sub-samples), in tasks of whole OpenVDB leaf depth: 8 voxel layers in z by a
/// band of 8 x b voxel rows in y, all columns. Each task accumulates dense per-voxel sums, turns
/// them into the values of its 8^3 leaves and builds their OpenVDB leaf nodes (io::VdbLeaves: no
/// locks, no shared tree); a serial stage hands the tasks' leaves to the grids in task order
/// (io::VdbVolume, io/vdb_volume.hpp). The file is streamed to a temporary name in the folder;
/// its random header UUID is replaced in place by one derived from the SHA-256 of the file with
/// the UUID zeroed; then fsync and a rename: same inputs and options give byte-identical files
/// for any thread count, and a reader never sees a partial file.
///
/// Cost: one sampler evaluation per sub-sample inside the model's leaf regions (N^3 per voxel;
/// void far from the model costs nothing), plus O(properties + materials) per inside sub-sample
/// (and 3 pow for the linear colour of a model with r, g, b).
/// Memory: the finished grids (about 4 x (7 + materials + properties) bytes per active voxel,
/// plus OpenVDB's node overhead), plus per worker one task's dense sums. Writing streams; the
/// file is hashed twice (about 1 s per GB).
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "trivox/slice/sampler.hpp"
#include "trivox/vmodel/vmodel.hpp"

namespace trivox::job {

/// The world unit of the grids' transform (`--vdb-units`): the model's millimetres, or metres
/// (scale and translation divided by 1000: what Blender and Houdini take the transform as).
enum class VdbUnits { mm, m };

/// What the `color` and `Cd` grids hold (`--vdb-color-space`): linear RGB (the palette's and
/// the model's sRGB colours decoded by io::srgb_to_linear, then mixed), or the sRGB-encoded
/// values mixed as they are.
enum class VdbColorSpace { linear, srgb };

/// "mm" or "m" to VdbUnits; false for any other name (out unchanged).
bool vdb_units_from_name(std::string_view name, VdbUnits& out) noexcept;
/// "mm" or "m".
const char* vdb_units_name(VdbUnits units) noexcept;
/// "linear" or "srgb" to VdbColorSpace; false for any other name (out unchanged).
bool vdb_color_space_from_name(std::string_view name, VdbColorSpace& out) noexcept;
/// "linear" or "srgb".
const char* vdb_color_space_name(VdbColorSpace space) noexcept;

/// Options of the VDB output (`trivox slice --vdb`).
struct VdbJobOptions {
  std::filesystem::path out_dir;      ///< the folder; the file is out_dir / (model stem + ".vdb")
  std::filesystem::path model_file;   ///< the source model file: its stem names the .vdb, its
                                      ///< name and SHA-256 go into the metadata (may be empty)
  std::optional<std::filesystem::path> palette;  ///< palette file; the default palette when empty
  std::optional<double> voxel_mm;     ///< voxel edge in mm; automatic when empty (see plan_vdb_job)
  int supersample = 1;                ///< N: N^3 sub-samples per voxel, 1..8
  VdbUnits units = VdbUnits::mm;      ///< the transform's world unit (the file's `units` metadata)
  VdbColorSpace color_space = VdbColorSpace::linear;  ///< what color/Cd hold (`color_space` metadata)
  bool force = false;                 ///< write into a non-empty folder; allow dense boxes beyond the limit
  bool require_empty_folder = true;   ///< false when the PNG stack was just written into out_dir
  std::int64_t max_dense_voxels = 2'000'000'000;      ///< refuse larger boxes unless force
  std::int64_t target_active_voxels = 50'000'000;     ///< what the automatic voxel size aims below
  /// The memory the job may use (`--max-memory`): the automatic voxel size keeps the estimate
  /// (VdbPlan::estimated_memory_bytes) within it, and a `voxel_mm` whose estimate exceeds it
  /// is refused. 2 GiB by default.
  std::int64_t max_memory_bytes = std::int64_t{2} << 30;
  /// Only the voxel layers [first, end) in z, first a multiple of 8 and end a multiple of 8 or
  /// the layer count (whole leaves): a shard's part, whose trees merged with the other parts'
  /// give the whole job's. Empty: every layer.
  std::optional<std::array<int, 2>> layer_range;
  std::string file_name;              ///< the file's name in out_dir; empty: <model stem>.vdb
  slice::SamplerOptions sampler;      ///< sampling options (the Shepard blend, --blend)
  /// What plan_vdb_job measures on the model, when an earlier plan has it already
  /// (VdbPlan::model_box and estimated_volume_mm3): slice::model_bounds(model) and the sum of the
  /// cells' |volume|. Each saves its computation (on the filleted teapot 0.4 s and 0.5 s); empty:
  /// computed.
  std::optional<std::array<slice::Vec3, 2>> model_box;
  std::optional<double> model_volume_mm3;
  /// Plan, then time a few tasks in memory (VdbJobSummary::estimated_seconds) without creating
  /// the folder or writing anything (`--dry-run`).
  bool dry_run = false;
  /// The SHA-256 of model_file's bytes (hex), when the caller has it already (`trivox slice`
  /// hashes the model once for its manifest); empty: computed from model_file.
  std::string model_sha256;
};

/// The grid a VDB job will use, found before anything is written.
struct VdbPlan {
  double voxel_mm = 0.0;
  bool automatic = false;                ///< the voxel size was chosen from the volume
  int supersample = 1;
  std::array<double, 3> origin{};        ///< minimum corner of the model's bounding box, mm
  std::array<std::array<double, 3>, 2> model_box{};  ///< the model's bounding box (model_bounds), mm
  std::array<int, 3> count{};            ///< voxels of the dense box along x, y, z
  std::int64_t dense_voxels = 0;         ///< count[0] * count[1] * count[2]
  double estimated_volume_mm3 = 0.0;     ///< sum of |cell volume| by Gauss quadrature (trivox info)
  double estimated_active_voxels = 0.0;  ///< estimated_volume_mm3 / voxel^3
  int grids_values = 0;                  ///< floats stored per active voxel (density, colour, fractions, properties)
  /// The job's peak memory, estimated (an upper estimate, within about 10 percent on the
  /// examples): a base of 150 MB (the model and its locator) + the active voxels of this job's
  /// layers x grids_values x 4 bytes x 1.2 (OpenVDB's leaves also hold their inactive voxels'
  /// values near the surface) + each worker's task sums.
  double estimated_memory_bytes = 0.0;
  std::filesystem::path file;            ///< out_dir / (stem + ".vdb")
};

/// What a VDB job wrote.
struct VdbJobSummary {
  VdbPlan plan;
  std::filesystem::path file;
  std::vector<std::string> grids;         ///< grid names in file order
  std::int64_t active_voxels = 0;
  std::int64_t fractional_voxels = 0;     ///< active voxels with density below 1
  std::int64_t samples = 0;               ///< sub-samples taken (dense box x N^3)
  std::int64_t inversion_failures = 0;    ///< sub-samples whose inversion did not settle
  double volume_mm3 = 0.0;                ///< sum of density x voxel volume
  std::vector<std::string> materials;     ///< palette names
  std::vector<double> material_volume_mm3;  ///< sum of fraction x density x voxel volume
  std::string colour_source;              ///< "r,g,b" or "palette"
  std::string units;                      ///< the file's world unit: "mm" or "m"
  std::string color_space;                ///< what color/Cd hold: "linear" or "srgb"
  std::string palette;                    ///< palette name
  std::string sha256;                     ///< of the written file
  std::int64_t bytes = 0;                 ///< file size
  double seconds = 0.0;
  int tasks = 0;                          ///< tasks of the job (slabs of 8 layers by bands of rows)
  bool dry_run = false;                   ///< nothing was written; the figures are estimates
  int timed_tasks = 0;                    ///< a dry run's tasks timed in memory
  double estimated_seconds = 0.0;         ///< a dry run's wall-time estimate: mean task CPU x tasks / threads
};

/// Progress: tasks done of total, sub-samples done, seconds since the start.
using VdbProgress = std::function<void(int tasks_done, int tasks_total, std::int64_t samples_done, double seconds)>;

/// Checks the options and finds the grid. The automatic voxel size is the smallest of the form
/// d x 10^e (d with 2 significant digits) at least cbrt(volume / target_active_voxels), at
/// least cbrt(box volume / max_dense_voxels) so the dense box stays within the limit, and large
/// enough that the estimated memory stays within max_memory_bytes.
/// @throws Error (bad_input) for a model without cells, a voxel size that is not positive and
///         finite, a supersample outside 1..8, a dense box beyond max_dense_voxels (unless force),
///         a voxel_mm whose estimated memory exceeds max_memory_bytes (force does not lift it:
///         raise max_memory_bytes), a max_memory_bytes too small for any voxel
///         or beyond 2^30 voxels along an axis (with the supersample), a layer range that is
///         not made of whole 8-layer blocks of the grid
VdbPlan plan_vdb_job(const vmodel::VModel& model, const VdbJobOptions& options);

/// Runs the job (plan_vdb_job first). The folder is created if absent; with
/// require_empty_folder it must be empty unless force.
/// @throws Error (bad_input) as plan_vdb_job, for an unusable folder or a malformed palette;
///         (failed) when writing fails
VdbJobSummary run_vdb_job(const vmodel::VModel& model, const VdbJobOptions& options,
                          const VdbProgress& progress = {});

}  // namespace trivox::job
