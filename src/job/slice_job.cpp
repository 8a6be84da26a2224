#include "trivox/job/slice_job.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <functional>
#include <future>
#include <map>
#include <optional>
#include <system_error>
#include <unistd.h>

#include "../io/png_codec.hpp"
#include "../io/png_rows.hpp"
#include "thread_time.hpp"
#include "trivox/job/archive_mesh.hpp"
#include "trivox/byte_size.hpp"
#include "trivox/error.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/io/safe_path.hpp"
#include "trivox/io/sha256.hpp"
#include "trivox/io/gcvf.hpp"
#include "trivox/io/png_image.hpp"
#include "trivox/io/stack_config.hpp"
#include "trivox/version.hpp"
#include "trivox/slice/dither.hpp"
#include "trivox/slice/material.hpp"
#include "trivox/slice/sampler.hpp"

namespace trivox::job {

namespace fs = std::filesystem;

namespace {

using detail::thread_cpu_seconds;

/// The memory estimate's size of an encoded slice in flight (SliceJobEstimate::memory_bytes).
constexpr double encoded_bytes_per_pixel = 0.5;
/// And what a job holds whatever its layers: the threads' stacks, the encoder's and the
/// pipeline's state (15 to 19 MB measured beyond the buffers on small layers).
constexpr double fixed_job_bytes = 32.0 * 1024 * 1024;


/// A number as a user would type it: 0.027, not 0.027000.
std::string text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return std::string(buf);
}

void check_profile(const slice::PrintProfile& p) {
  if (!(std::isfinite(p.dpi_x) && std::isfinite(p.dpi_y) && p.dpi_x >= 10 && p.dpi_x <= 10000 && p.dpi_y >= 10 &&
        p.dpi_y <= 10000))
    throw Error("--dpi " + text(p.dpi_x) + "," + text(p.dpi_y) +
                ": out of range; expected 10 to 10000 dots per inch in x and y");
  if (!(std::isfinite(p.layer_mm) && p.layer_mm >= 0.001 && p.layer_mm <= 10.0))
    throw Error("--layer " + text(p.layer_mm) + ": out of range; expected a layer of 0.001 to 10 mm");
}

/// ConfigFile.xml holds the resolution and the layer as integers (dots per inch, nanometres),
/// and every reader parses them so: a job whose numbers are not whole would be printed at
/// another size. The layer allows the binary noise of mm * 1e6 (0.027 mm is 27000.000000000004).
void check_voxel_print_numbers(const slice::PrintProfile& p) {
  if (p.dpi_x != std::floor(p.dpi_x) || p.dpi_y != std::floor(p.dpi_y))
    throw Error("--dpi " + text(p.dpi_x) + "," + text(p.dpi_y) +
                ": not whole dots per inch; expected integers (ConfigFile.xml's XDpi and YDpi are integers), e.g. 600,300");
  const double nm = p.layer_mm * 1e6;
  if (std::abs(nm - std::round(nm)) > 1e-6) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.10g", nm);
    throw Error("--layer " + text(p.layer_mm) + ": " + buf +
                " nm, not a whole number of nanometres; expected a layer of whole nanometres (ConfigFile.xml's "
                "SliceThicknessNanoMeter is an integer), e.g. 0.027");
  }
}

bool is_manifest_name(const std::string& name) {
  return name == "manifest.json" || (name.starts_with("manifest.shard-") && name.ends_with(".json"));
}

/// A manifest's journal (manifest.hpp, journal_name_of).
bool is_journal_name(const std::string& name) {
  return name == "manifest.journal" || (name.starts_with("manifest.shard-") && name.ends_with(".journal"));
}

/// Per-worker scratch, reused across layers so a job allocates once per thread.
struct Scratch {
  slice::RowBand band;
  std::optional<slice::LayerDitherer> dither;  ///< its error rows, allocated once per thread
  std::vector<std::uint8_t> rgba;
  // Grouped layers (slice::LayerGroupDitherer): a band and the material indices of each layer
  // of a group (a byte per pixel, painted while they are encoded).
  std::optional<slice::LayerGroupDitherer> group;
  std::vector<slice::RowBand> bands;
  std::vector<std::vector<std::uint8_t>> indices;
  std::array<double, 5> seconds{};  ///< per stage, see SliceJobSummary::stage_seconds
};

using Clock = std::chrono::steady_clock;

/// What the process holds in memory now (resident pages, /proc/self/statm); 0 where unknown.
double resident_bytes() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (f == nullptr) return 0.0;
  long long size = 0, resident = 0;
  const int n = std::fscanf(f, "%lld %lld", &size, &resident);
  std::fclose(f);
  return n == 2 ? static_cast<double>(resident) * static_cast<double>(::sysconf(_SC_PAGESIZE)) : 0.0;
}

/// Adds this thread's CPU time since `t` to `acc` and moves `t` to now.
inline void lap(double& t, double& acc) {
  const double now = thread_cpu_seconds();
  acc += now - t;
  t = now;
}

/// Runs `f` when the scope is left by an exception (not on a normal exit), swallowing what `f`
/// throws: the exception in flight is the one to report.
class OnUnwind {
public:
  explicit OnUnwind(std::function<void()> f) : f_(std::move(f)), exceptions_(std::uncaught_exceptions()) {}
  OnUnwind(const OnUnwind&) = delete;
  OnUnwind& operator=(const OnUnwind&) = delete;
  ~OnUnwind() {
    if (std::uncaught_exceptions() > exceptions_) try {
        f_();
      } catch (...) {
      }
  }

private:
  std::function<void()> f_;
  int exceptions_;
};

/// One layer on its way through the pipeline.
struct LayerOut {
  int layer = -1;
  std::string png;
  std::vector<std::int64_t> counts;
  std::int64_t failures = 0;
  std::string sha256;  ///< of png
};


/// A note to the user on stderr: what a job did to a folder beyond writing its own files.
void note(const std::string& text) { std::fprintf(stderr, "trivox: note: %s\n", text.c_str()); }

bool is_png_job(const Manifest& id) { return id.options.count("png") == 0 || id.options.at("png") != "no"; }

/// "slice_<digits>.png": a file of trivox's slice naming, and its number.
std::optional<long long> slice_number(const std::string& name) {
  const std::string head = io::StackConfig{}.prefix, tail = ".png";
  if (name.size() <= head.size() + tail.size() || !name.starts_with(head) || !name.ends_with(tail)) return std::nullopt;
  const std::string digits = name.substr(head.size(), name.size() - head.size() - tail.size());
  if (digits.size() > 18 || !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return std::nullopt;
  return std::stoll(digits);
}

/// Whether `name` is one of the outputs of job `id` (this shard's, for a shard): its slices, its
/// manifest and journal, ConfigFile.xml and the VDB of a whole job, its own VDB part and write
/// probe, and the archive's Mesh.stl (a whole job's, shard 0's).
bool job_output_name(const Manifest& id, const std::string& name) {
  const bool whole = id.shard.count == 1;
  if (const auto n = slice_number(name)) return whole || (*n >= id.layer_range[0] && *n < id.layer_range[1]);
  if (whole)
    return is_manifest_name(name) || is_journal_name(name) || name == "ConfigFile.xml" || name == vdb_file_name(id) ||
           name == archive_mesh_name || name.starts_with(".trivox-write-test");
  if (id.shard.index == 0 && name == archive_mesh_name) return true;
  return name == id.shard.manifest_name() || name == id.shard.journal_name() || name == id.shard.part_name(vdb_file_name(id)) ||
         name == ".trivox-write-test-" + std::to_string(id.shard.index);
}

/// Moves a manifest that does not parse out of the way: `NAME.damaged-<n>`, the first n free.
std::string move_aside(const fs::path& dir, const std::string& name) {
  std::error_code ec;
  for (int n = 1; n < 1000000; ++n) {
    const std::string to = name + ".damaged-" + std::to_string(n);
    if (fs::exists(fs::symlink_status(dir / to, ec))) continue;
    fs::rename(dir / name, dir / to, ec);
    if (ec)
      throw Error((dir / name).string() + ": cannot move it aside (" + ec.message() +
                  "); expected a folder that --force may write");
    return to;
  }
  throw Error((dir / name).string() + ": cannot move it aside: every name " + name +
              ".damaged-<n> is taken; expected a folder that --force may write");
}

/// What --force (without --resume) removes before a job writes anything, in a folder that holds
/// a readable trivox manifest, so that the folder ends up holding this job alone and never looks
/// complete while it does not: ConfigFile.xml first (a stack without it is unfinished to every
/// reader), then the files the earlier jobs' manifests list in the folder (their VDB) when their
/// bytes still have the recorded SHA-256, then the slices (trivox's naming, `slice_<n>.png`) this
/// job will not overwrite (past the new stack's end; all of them for a volume-only job), then the
/// earlier manifests (last, so that a kill midway leaves a manifest and the next --force finishes
/// the work). Slices it will overwrite stay until replaced (each by a rename): removing them
/// first would double the folder's metadata writes, about 3.5 ms a file on a journalling disk,
/// for a folder that already says it is unfinished. Sibling shards share the folder: only the
/// last removes slices past the end, and none removes a manifest of the same job, so none
/// removes another's work. Files of other names stay, and so does a listed file whose bytes
/// changed (said on stderr).
/// @param stale  the manifests in `dir` to remove (file name, content), with the files they list
void clear_earlier_job(const fs::path& dir, const Manifest& id, const std::vector<std::pair<std::string, Manifest>>& stale) {
  const auto remove = [&](const fs::path& p) {
    std::error_code ec;
    fs::remove(p, ec);
    if (ec) throw Error(p.string() + ": cannot remove what an earlier job left (" + ec.message() +
                        "); expected a folder that --force may overwrite");
  };
  remove(dir / "ConfigFile.xml");
  for (const auto& [name, m] : stale)
    for (const ManifestFile& f : m.files) {
      // The archive lives beside the folder, outside it: a job with --zip replaces it.
      if (f.role != "vdb" && f.role != "mesh") continue;
      // parse_manifest checked the name: a plain name inside the folder.
      const fs::path p = dir / f.file;
      const auto sha = io::sha256_regular_file(p);
      if (sha == f.sha256) remove(p);
      else if (sha || fs::exists(fs::symlink_status(p)))
        note(p.string() + ": kept: listed by " + name + " but not the file it lists (changed since, or not a regular file)");
    }
  const bool png = is_png_job(id);
  const bool last = id.shard.index == id.shard.count - 1;
  if (!png || last)
    for (const auto& [n, name] : io::detail::list_slices(dir, io::StackConfig{}.prefix))
      if (!png || n >= id.layer_range[1]) remove(dir / name);
  for (const auto& [name, m] : stale) {
    remove(dir / journal_name_of(name));
    remove(dir / name);
  }
}

}  // namespace

std::optional<Manifest> prepare_job_folder(const fs::path& dir, const Manifest& id, bool force, bool resume) {
  std::error_code ec;
  std::optional<Manifest> own;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec))
      throw Error(dir.string() + ": exists and is not a folder; expected a new or empty folder for the slices");
    bool empty = true, same_job_there = false, trivox_folder = false;
    std::vector<std::pair<std::string, Manifest>> stale;  // manifests that --force removes
    std::vector<std::string> damaged;                      // manifest names that do not parse
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
      const std::string name = entry.path().filename().string();
      if (name.starts_with(".trivox-write-test")) continue;
      empty = false;
      if (!is_manifest_name(name)) continue;
      std::optional<Manifest> m;
      try {
        m = read_manifest(dir, name);
      } catch (const Error& e) {
        // Damaged, foreign (another program's manifest.json) or a link: --force moves it aside.
        if (force) {
          damaged.push_back(name);
          continue;
        }
        throw Error(std::string(e.what()) +
                    (resume ? " (--resume cannot continue from it; --force moves it aside and starts over)"
                            : " (--force moves it aside and starts over)"));
      }
      if (!m) continue;  // gone since the listing
      trivox_folder = true;
      if (const std::string why = id.difference(*m); !why.empty()) {
        if (!force)
          throw Error(dir.string() + ": holds another job (" + name + ": " + why +
                      "); expected the same model and options to resume or add shards (or --force to overwrite, or "
                      "another folder)");
        stale.emplace_back(name, *m);
        continue;
      }
      same_job_there = true;
      if (name == id.shard.manifest_name()) own = *m;
      // Without --resume this job's own manifest is superseded, and with --force a whole job's
      // supersedes a sharded run's parts.
      if (force && !resume && (name == id.shard.manifest_name() || id.shard.count == 1)) {
        stale.emplace_back(name, *m);
      }
    }
    if (!empty && !force && !resume && id.shard.count == 1)
      throw Error(dir.string() + ": the folder is not empty; expected a new or empty folder (" +
                  (same_job_there ? std::string("--resume to continue (or verify) the job there, ") : std::string()) +
                  "or --force to overwrite)");
    for (const std::string& name : damaged)
      note((dir / name).string() + ": not a manifest this trivox can read (damaged, another program's, or a link); moved aside to " +
           move_aside(dir, name) + ", starting over");
    if (!empty && force && !resume) {
      if (trivox_folder) {
        clear_earlier_job(dir, id, stale);
      } else if (id.shard.count == 1) {
        // Nothing proves that trivox wrote any file here: none is removed. The job's own names
        // are replaced as it writes them; slices past its end stay, and are said.
        long long beyond = 0;
        const bool png = is_png_job(id);
        for (const auto& [n, name] : io::detail::list_slices(dir, io::StackConfig{}.prefix))
          if (!png || n >= id.layer_range[1]) ++beyond;
        note(dir.string() + ": holds no trivox manifest, so --force removes nothing there: the files this job writes "
             "replace any of the same names, and every other file stays" +
             (beyond ? " (among them " + std::to_string(beyond) + " slice file(s) " +
                           (png ? "past this job's last layer" : "of a PNG stack") + ")"
                     : std::string()));
      }
    }
    if (force || resume) {
      const int removed = io::remove_stale_temporaries(dir, [&](const std::string& owner) { return job_output_name(id, owner); });
      if (removed > 0) note(dir.string() + ": removed " + std::to_string(removed) + " temporary file(s) left by an earlier run");
    }
  } else if ((!fs::create_directories(dir, ec) || ec) && !fs::is_directory(dir)) {  // a sibling shard may win
    throw Error(dir.string() + ": cannot create the folder (" + ec.message() + "); expected a writable location");
  }
  // Probe writability now rather than after the first layer (a name of this shard's own).
  const fs::path probe = dir / (".trivox-write-test" + (id.shard.count > 1 ? "-" + std::to_string(id.shard.index) : std::string()));
  try {
    io::write_file_atomically(probe, "", io::Durability::deferred);  // removed at once: no fsync
  } catch (const Error& e) {
    throw Error(dir.string() + ": the folder is not writable; expected a writable folder");
  }
  fs::remove(probe, ec);
  if (!resume) own.reset();
  return own;
}

namespace {
/// The model's box and the profile's grid over it (model_bounds once: a thousand-span cell's
/// Bezier form takes seconds).
std::pair<std::array<slice::Vec3, 2>, slice::VoxelGrid> box_and_grid(
    const vmodel::VModel& model, const slice::PrintProfile& profile,
    const std::optional<std::array<slice::Vec3, 2>>& known = std::nullopt, const std::string& name = "the model") {
  if (model.cells.empty())
    throw Error(name + ": no cells; expected at least one volumetric cell (a trivariate) to slice");
  check_profile(profile);
  const auto box = known ? *known : slice::model_bounds(model);
  slice::check_solid_box(box[0], box[1], name);
  return {box, slice::VoxelGrid::covering(box[0], box[1], {profile.pitch_x(), profile.pitch_y(), profile.pitch_z()})};
}
}  // namespace

slice::VoxelGrid slice_grid(const vmodel::VModel& model, const slice::PrintProfile& profile) {
  return box_and_grid(model, profile).second;
}

SliceJobSummary run_slice_job(const vmodel::VModel& model, const SliceJobOptions& opt, const SliceProgress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto box_grid = box_and_grid(model, opt.profile, opt.model_box, opt.model_name);
  const auto& box = box_grid.first;
  const slice::VoxelGrid& grid = box_grid.second;

  // Size checks before anything is written.
  const double bytes = static_cast<double>(grid.voxels()) * 4.0;
  const std::string estimate = std::to_string(grid.count[0]) + " x " + std::to_string(grid.count[1]) + " x " +
                               std::to_string(grid.count[2]) + " = " + std::to_string(grid.voxels()) + " voxels, " +
                               file_size_text(bytes) + " of RGBA pixels before compression";
  if (!opt.force) {
    static constexpr const char* axis = "xyz";
    for (int d = 0; d < 3; ++d) {
      const auto dd = static_cast<std::size_t>(d);
      if (box[1][dd] - box[0][dd] > opt.profile.tray_mm[dd])
        throw Error(opt.model_name + ": the model is " + text(box[1][dd] - box[0][dd]) + " mm along " + axis[d] +
                    ", larger than the " + opt.profile.name + " tray (" + text(opt.profile.tray_mm[dd]) +
                    " mm); expected a model that fits (or --force). Job: " + estimate);
    }
  }
  // The output's size: limits that --force does not lift (it is for folders and trays).
  if (grid.voxels() > opt.max_voxels)
    throw Error(opt.model_name + ": the job has " + estimate + "; expected at most " + std::to_string(opt.max_voxels) +
                " voxels (limit --max-voxels; raise it with --max-voxels N)");
  if (grid.count[2] > opt.max_layers)
    throw Error(opt.model_name + ": the job has " + std::to_string(grid.count[2]) + " layers (" +
                text(box[1][2] - box[0][2]) + " mm in layers of " + text(opt.profile.layer_mm) +
                " mm), a file each; expected at most " + std::to_string(opt.max_layers) +
                " (limit --max-layers; raise it with --max-layers N, or a thicker --layer)");

  check_voxel_print_numbers(opt.profile);
  if (opt.digits < 0 || opt.digits > 9)
    throw Error("--digits " + std::to_string(opt.digits) + ": out of range; expected 0 (no padding: slice_7.png) to 9");
  const std::array<std::uint8_t, 4> background = io::stack_background(opt.background);

  // The PNG module now (png_codec.hpp): when it cannot be loaded the job stops here, before a
  // folder is made or a layer sampled.
  (void)io::detail::png_codec();

  const slice::Palette palette = opt.palette ? slice::load_palette(*opt.palette) : slice::default_palette();
  const std::string palette_source = opt.palette ? opt.palette->string() : std::string("the built-in palette");
  if (static_cast<int>(palette.materials.size()) > opt.profile.channels) {
    std::string names;
    for (const auto& m : palette.materials) names += (names.empty() ? "" : ", ") + m.name;
    throw Error(palette_source + ": " + std::to_string(palette.materials.size()) + " materials (" + names + "); the " +
                opt.profile.name + " holds " + std::to_string(opt.profile.channels) +
                " at once; expected a palette of at most " + std::to_string(opt.profile.channels) +
                " materials (or a printer with more channels)");
  }
  for (const auto& m : palette.materials)
    if (m.rgba == background)
      throw Error(palette_source + ": material " + m.name + " is coloured " + io::detail::rgba_text(m.rgba.data()) +
                  ", the void colour of --background " + opt.background +
                  "; expected material colours other than the background (or --background transparent)");
  const slice::MaterialMapper mapper(palette, model.properties, opt.palette ? opt.palette->string() : std::string());
  const slice::DitherMode mode = slice::parse_dither_mode(opt.dither);

  // Every dithering mode reads a voxel's cell before its properties, so void voxels' need not
  // be cleared.
  slice::SamplerOptions sampling = opt.sampler;
  sampling.zero_void_props = false;
  const slice::LayerSampler sampler(model, grid, sampling);
  const int nx = grid.count[0], ny = grid.count[1], nz = grid.count[2];
  const int nmat = mapper.materials();
  const int nprops = static_cast<int>(model.properties.size());
  const int band_rows = std::max(1, std::min(opt.band_rows, ny));


  // Pixel colours by material index; 255 (void) and unused indices are the background.
  std::array<std::uint32_t, 256> colour{};
  std::uint32_t void_colour = 0;
  std::memcpy(&void_colour, background.data(), 4);
  colour.fill(void_colour);
  for (int m = 0; m < nmat; ++m) std::memcpy(&colour[static_cast<std::size_t>(m)], palette.materials[static_cast<std::size_t>(m)].rgba.data(), 4);

  // The job's identity and the folder; when resuming, the layers that are done and verify.
  Manifest manifest;
  manifest.trivox = version;
  manifest.model_file = opt.model_file.empty() ? opt.model_name : opt.model_file;
  manifest.model_sha256 = opt.model_sha256;
  manifest.options = opt.extra_options;
  manifest.options["png"] = "yes";
  manifest.options["png.dpi"] = option_number(opt.profile.dpi_x) + "," + option_number(opt.profile.dpi_y);
  manifest.options["png.layer_mm"] = option_number(opt.profile.layer_mm);
  manifest.options["png.printer"] = opt.profile.name;
  manifest.options["png.palette"] = palette.name + (opt.palette ? " " + io::sha256_file(*opt.palette) : std::string(" (built in)"));
  manifest.options["png.dither"] = std::string(slice::dither_mode_name(mode));
  manifest.options["png.zip"] = opt.zip ? "yes" : "no";
  manifest.options["png.digits"] = std::to_string(opt.digits);
  manifest.options["png.background"] = opt.background;
  manifest.options["png.channels"] = std::to_string(opt.profile.channels);
  manifest.grid = grid.count;
  manifest.dpi_x = opt.profile.dpi_x;
  manifest.dpi_y = opt.profile.dpi_y;
  manifest.layer_mm = opt.profile.layer_mm;
  for (const auto& mat : palette.materials) {
    manifest.materials.push_back(mat.name);
    manifest.colours.push_back(mat.rgba);
  }
  manifest.shard = opt.shard;
  manifest.layer_range = opt.shard.range(nz);
  io::StackConfig cfg = stack_config_of(manifest, {});

  tbb::enumerable_thread_specific<Scratch> scratch;
  // The workers available: the arena's, within a global limit (--threads).
  const int cores = static_cast<int>(std::min<std::size_t>(
      static_cast<std::size_t>(tbb::this_task_arena::max_concurrency()),
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)));

  // Work items are groups of layers. On the colour path with fs, a group of up to 8 layers is
  // dithered together, one layer per vector lane (slice::LayerGroupDitherer: the same pixels as
  // one layer at a time, at a fraction of the cost), when each thread's group of index buffers
  // (a byte per pixel) fits in group_budget / threads and the job's memory within
  // max_memory_bytes; otherwise every group is one layer. The groups split the layers to do into
  // a multiple of the thread count of nearly equal sizes, so that no thread is left with a last
  // group alone.
  constexpr double group_budget = 1024.0 * 1024.0 * 1024.0;  // bytes of index layers in all groups
  const double layer_bytes = static_cast<double>(nx) * static_cast<double>(ny);
  // TRIVOX_LAYER_GROUP=N caps the group size (diagnostics and tests: the output is the same).
  int group_cap = slice::LayerGroupDitherer::max_layers;
  if (const char* env = std::getenv("TRIVOX_LAYER_GROUP"))
    group_cap = std::clamp(std::atoi(env), 1, slice::LayerGroupDitherer::max_layers);
  bool grouped = group_cap >= 3 && slice::LayerGroupDitherer::serves(mode, mapper) &&
                 group_cap * layer_bytes * cores <= group_budget;

  // Memory (SliceJobEstimate): what the process holds, and per worker its buffers and the
  // encoded layers it has in flight, half a byte per pixel each (slices of a random-looking
  // mix of 6 materials compress to about 0.4, solid parts to a few hundredths), and one more
  // work item waiting for the writer. The workers are as many as fit in max_memory_bytes,
  // ungrouped if need be: the output does not depend on their count.
  const double base_bytes = resident_bytes();
  const double band_bytes = static_cast<double>(band_rows) * nx * (4.0 + 4.0 * nprops);
  auto worker_bytes = [&](bool group) {
    const int g = group ? group_cap : 1;
    const double buffers = group ? g * (layer_bytes + std::min(band_rows, 2 * slice::LayerSampler::block_rows) * nx * (4.0 + 4.0 * nprops))
                                 : 4.0 * layer_bytes + band_bytes;
    return buffers + g * encoded_bytes_per_pixel * layer_bytes;  // and its encoded layers
  };
  auto job_bytes = [&](int w, bool group) {
    return base_bytes + fixed_job_bytes + w * worker_bytes(group) + (group ? group_cap : 1) * encoded_bytes_per_pixel * layer_bytes;
  };
  int threads = cores;
  if (grouped && job_bytes(threads, true) > static_cast<double>(opt.max_memory_bytes)) grouped = false;
  while (threads > 1 && job_bytes(threads, grouped) > static_cast<double>(opt.max_memory_bytes)) --threads;
  if (job_bytes(threads, grouped) > static_cast<double>(opt.max_memory_bytes))
    throw Error("--max-memory " + memory_size_text(static_cast<double>(opt.max_memory_bytes)) + ": the job needs about " +
                memory_size_text(job_bytes(1, false)) + " with one worker (" + memory_size_text(base_bytes) + " held already, " +
                std::to_string(nx) + " x " + std::to_string(ny) + " pixels a layer); expected a limit above it " +
                "(raise --max-memory, or a coarser --dpi)");
  const int tokens = threads + 1;
  SliceJobEstimate est;
  est.threads = threads;
  est.grouped = grouped;
  est.base_bytes = base_bytes;
  est.memory_bytes = job_bytes(threads, grouped);

  // A layer's PNG, from its pixels (RGBA) or its material indices, and the PNG's digest.
  auto encode = [&](LayerOut& out, const std::uint8_t* pixels, bool indexed) {
    out.png = indexed ? io::encode_png_indexed(pixels, nx, ny, colour, cfg.dpi_x, cfg.dpi_y)
                      : io::encode_png_rgba(pixels, nx, ny, cfg.dpi_x, cfg.dpi_y);
    out.sha256 = io::sha256_hex(out.png);
  };

  auto sample_layer = [&](int k) {
    LayerOut out;
    out.layer = k;
    Scratch& s = scratch.local();
    s.rgba.resize(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) * 4);
    std::vector<std::int64_t> counts(static_cast<std::size_t>(nmat), 0);
    if (!s.dither) s.dither.emplace(mode, nx, nmat, grid.pitch[0], grid.pitch[1]);
    slice::LayerDitherer& dither = *s.dither;
    dither.begin_layer(k);
    double t = thread_cpu_seconds();
    for (int r0 = 0; r0 < ny; r0 += band_rows) {
      const int rows = std::min(band_rows, ny - r0);
      sampler.sample(k, r0, rows, s.band);
      lap(t, s.seconds[0]);
      out.failures += s.band.failures;
      // Row by row: map, dither and paint in one pass (LayerDitherer::dither_paint), so nothing
      // but the pixels leaves the L1/L2 cache.
      const auto unx = static_cast<std::size_t>(nx);
      for (int r = 0; r < rows; ++r) {
        const std::int32_t* cell = s.band.cell.data() + static_cast<std::size_t>(r) * unx;
        dither.dither_paint(r0 + r, cell, s.band.props.data() + static_cast<std::size_t>(r) * unx * static_cast<std::size_t>(nprops),
                            mapper, colour, s.rgba.data() + static_cast<std::size_t>(r0 + r) * unx * 4, counts.data());
      }
      lap(t, s.seconds[2]);
    }
    out.counts = std::move(counts);
    encode(out, s.rgba.data(), false);
    lap(t, s.seconds[4]);
    return out;
  };

  // Groups of 3 or more layers take the grouped kernel (below that, the lanes it would leave
  // empty cost more than dithering the layers one by one).
  auto sample_group = [&](const std::vector<int>& layers) {
    std::vector<LayerOut> outs;
    const int n = static_cast<int>(layers.size());
    if (!grouped || n < 3) {
      for (int k : layers) outs.push_back(sample_layer(k));
      return outs;
    }
    Scratch& s = scratch.local();
    const auto un = static_cast<std::size_t>(n), unx = static_cast<std::size_t>(nx);
    if (!s.group) s.group.emplace(nx, mapper, grid.pitch[0], grid.pitch[1]);
    s.bands.resize(un);
    s.indices.resize(un);
    outs.resize(un);
    std::vector<std::vector<std::int64_t>> counts(un, std::vector<std::int64_t>(static_cast<std::size_t>(nmat), 0));
    const std::int32_t* cell[slice::LayerGroupDitherer::max_layers];
    const float* props[slice::LayerGroupDitherer::max_layers];
    std::uint8_t* index[slice::LayerGroupDitherer::max_layers];
    std::int64_t* count[slice::LayerGroupDitherer::max_layers];
    for (std::size_t i = 0; i < un; ++i) {
      s.indices[i].resize(unx * static_cast<std::size_t>(ny));
      outs[i].layer = layers[i];
      count[i] = counts[i].data();
    }
    s.group->begin(n);
    // Bands of a few sampler blocks, so that the group's bands stay in the L2 cache between the
    // sampler writing them and the ditherer reading them.
    const int group_rows = std::min(band_rows, 2 * slice::LayerSampler::block_rows);
    double t = thread_cpu_seconds();
    for (int r0 = 0; r0 < ny; r0 += group_rows) {
      const int rows = std::min(group_rows, ny - r0);
      for (std::size_t i = 0; i < un; ++i) {
        sampler.sample(layers[i], r0, rows, s.bands[i]);
        outs[i].failures += s.bands[i].failures;
      }
      lap(t, s.seconds[0]);
      for (int r = 0; r < rows; ++r) {
        const auto ur = static_cast<std::size_t>(r);
        for (std::size_t i = 0; i < un; ++i) {
          cell[i] = s.bands[i].cell.data() + ur * unx;
          props[i] = s.bands[i].props.data() + ur * unx * static_cast<std::size_t>(nprops);
          index[i] = s.indices[i].data() + (static_cast<std::size_t>(r0) + ur) * unx;
        }
        s.group->dither(r0 + r, cell, props, index, count);
      }
      lap(t, s.seconds[2]);
    }
    // The group's PNGs as tasks that an idle worker may take: without them, the thread that
    // finishes its last group first waits for the other's encodes, up to a group's time. Each
    // task times itself on the thread that runs it. Isolated, so that a thread waiting here
    // takes none of the pipeline's other groups (which would reuse its scratch).
    tbb::this_task_arena::isolate([&] {
      tbb::parallel_for(std::size_t{0}, un, [&](std::size_t i) {
        double te = thread_cpu_seconds();
        outs[i].counts = std::move(counts[i]);
        encode(outs[i], s.indices[i].data(), true);
        lap(te, scratch.local().seconds[4]);
      });
    });
    return outs;
  };

  // The estimate's time and size: a few layers, evenly spread over the range, sampled, dithered
  // and encoded in memory.
  constexpr int probe_layers = 8;
  const int range_layers = manifest.layer_range[1] - manifest.layer_range[0];
  if (opt.dry_run) {
    std::vector<int> probe;
    for (int q = 0; q < probe_layers; ++q) {
      const int k = manifest.layer_range[0] + static_cast<int>((static_cast<std::int64_t>(range_layers) * (2 * q + 1)) / (2 * probe_layers));
      if (k < manifest.layer_range[1] && (probe.empty() || probe.back() != k)) probe.push_back(k);
    }
    std::vector<double> cpu(probe.size()), bytes(probe.size());
    tbb::task_arena arena(threads);
    arena.execute([&] {
      tbb::parallel_for(std::size_t{0}, probe.size(), [&](std::size_t i) {
        const double c0 = thread_cpu_seconds();
        bytes[i] = static_cast<double>(sample_layer(probe[i]).png.size());
        cpu[i] = thread_cpu_seconds() - c0;
      });
    });
    double cpu_sum = 0.0, bytes_sum = 0.0;
    for (std::size_t i = 0; i < probe.size(); ++i) {
      cpu_sum += cpu[i];
      bytes_sum += bytes[i];
    }
    est.timed_layers = static_cast<int>(probe.size());
    est.seconds_per_layer = probe.empty() ? 0.0 : cpu_sum / static_cast<double>(probe.size());
    est.layers = range_layers;
    est.seconds = est.seconds_per_layer * range_layers / threads;
    est.output_bytes = probe.empty() ? 0.0 : bytes_sum / static_cast<double>(probe.size()) * range_layers;
  }
  if (opt.dry_run) {
    est.voxels = static_cast<std::int64_t>(range_layers) * grid.voxels_per_layer();
    est.files = range_layers + (opt.shard.count == 1 ? 2 : 1) + (opt.zip && opt.shard.index == 0 ? 1 : 0);
    SliceJobSummary sum;
    sum.grid = grid;
    sum.dry_run = true;
    sum.estimate = est;
    sum.layer_range = manifest.layer_range;
    sum.shard = opt.shard;
    sum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    for (const auto& mat : palette.materials) {
      sum.materials.push_back(mat.name);
      sum.colours.push_back(mat.rgba);
    }
    return sum;
  }

  // The archive's place is checked before the slices are written, not after.
  if (opt.zip) {
    const fs::path zip = io::gcvf_path(opt.out_dir);
    std::error_code ec;
    if (fs::is_directory(zip, ec))
      throw Error(zip.string() + ": is a folder; expected a .gcvf file path to write (--zip packs DIR as DIR.gcvf)");
    // A non-empty folder without --force or --resume is refused below, with its own reason;
    // shards' archive is merge's to write.
    const bool fresh = !fs::exists(opt.out_dir, ec) || fs::is_empty(opt.out_dir, ec);
    if (fs::exists(zip, ec) && fresh && !opt.force && !opt.resume && opt.shard.count == 1)
      throw Error(zip.string() + ": exists; expected a new archive (--force to replace it, or another output folder)");
  }
  const std::optional<Manifest> previous = prepare_job_folder(opt.out_dir, manifest, opt.force, opt.resume);

  std::map<int, ManifestLayer> finished;  // by layer
  std::vector<int> todo;
  {
    std::vector<char> keep(static_cast<std::size_t>(nz), 0);
    if (previous)
      tbb::parallel_for(manifest.layer_range[0], manifest.layer_range[1], [&](int k) {
        // A layer that is a symbolic link (to a file elsewhere, whose bytes may match) is redone:
        // the finished job must not depend on a file outside the folder. Its rename then
        // replaces the link itself.
        const ManifestLayer* l = previous->layer(k);
        const fs::path f = opt.out_dir / cfg.slice_name(k);
        keep[static_cast<std::size_t>(k)] = l && l->file == cfg.slice_name(k) && io::sha256_regular_file(f) == l->sha256;
      });
    for (int k = manifest.layer_range[0]; k < manifest.layer_range[1]; ++k)
      if (keep[static_cast<std::size_t>(k)]) finished.emplace(k, *previous->layer(k));
      else todo.push_back(k);
  }
  const int kept = static_cast<int>(finished.size());
  const int total_layers = manifest.layer_range[1] - manifest.layer_range[0];

  // The manifest is written whole twice: now, listing the layers kept, and at the end (or when
  // the job stops on an error), listing every finished layer. Between them the layers finished
  // are appended to its journal (apply_journal), a few seconds' worth at a time, so that keeping
  // the record costs time linear in the layers. Both list only layers already on disk: the
  // folder is synced first.
  const fs::path journal = opt.out_dir / manifest.shard.journal_name();
  auto write_manifest = [&](bool complete) {
    manifest.layers.clear();
    for (const auto& [k, l] : finished) manifest.layers.push_back(l);
    manifest.complete = complete;
    // A manifest listing no layer (a new job's first) vouches for no file: no sync needed (it
    // cost 3 ms here, a whole file system's dirty pages elsewhere).
    if (!manifest.layers.empty()) io::sync_folder_contents(opt.out_dir);
    const std::string text = manifest_json(manifest);
    io::write_file_atomically(opt.out_dir / manifest.shard.manifest_name(), text);
    return text;
  };
  // The journal of the manifest just written; removed once a later manifest lists its layers
  // (a journal left by a kill in between belongs to another manifest, so no reader takes it).
  io::write_file_atomically(journal, journal_header(write_manifest(false)));
  auto end_journal = [&] {
    std::error_code ec;
    fs::remove(journal, ec);
  };
  auto last_manifest = Clock::now();
  std::vector<ManifestLayer> unjournaled;  // finished, not yet in the journal
  // The journal's appends: their sync (which waits for the disk, seconds on a network share) runs
  // on a thread of its own, so that no worker waits for it; one at a time (a period whose
  // predecessor is still syncing is skipped, its layers go with the next).
  // std::async's future waits in its destructor, so an exception leaves no thread behind.
  std::future<void> pending_manifest;
  // A job that stops on an error from here on (a full disk, a failing layer) first writes a last
  // manifest listing the layers it finished, synced, so that --resume keeps them. Best effort:
  // when that fails too (the disk is full), the original error is the one reported.
  const OnUnwind last_words([&] {
    if (pending_manifest.valid()) pending_manifest.wait();
    write_manifest(false);
    end_journal();
  });
  auto write_manifest_behind = [&] {
    if (pending_manifest.valid()) {
      if (pending_manifest.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
      pending_manifest.get();  // rethrows its error
    }
    std::string lines;
    for (const ManifestLayer& l : unjournaled) lines += journal_line(l);
    unjournaled.clear();
    pending_manifest = std::async(std::launch::async, [lines = std::move(lines), dir = opt.out_dir, journal] {
      io::sync_folder_contents(dir);
      io::append_synced(journal, lines);
    });
    last_manifest = Clock::now();
  };

  est.layers = static_cast<int>(todo.size());
  est.voxels = static_cast<std::int64_t>(todo.size()) * grid.voxels_per_layer();
  est.files = est.layers + (opt.shard.count == 1 ? 2 : 1) + (opt.zip && opt.shard.index == 0 ? 1 : 0);
  int done = kept;
  std::vector<std::vector<int>> groups;
  {
    const int n = static_cast<int>(todo.size()), g = grouped ? group_cap : 1;
    int ng = (n + g - 1) / g;
    if (grouped) ng = std::min(n, (ng + threads - 1) / threads * threads);
    for (int i = 0, at = 0; i < ng; ++i) {
      const int size = n / ng + (i < n % ng ? 1 : 0);
      groups.emplace_back(todo.begin() + at, todo.begin() + at + size);
      at += size;
    }
  }
  std::size_t next = 0;

  const auto pipeline_t0 = Clock::now();
  // At most `threads` workers (fewer than the cores when max_memory_bytes says so).
  tbb::task_arena arena(threads);
  arena.execute([&] {
  tbb::parallel_pipeline(
      static_cast<std::size_t>(tokens),
      tbb::make_filter<void, std::size_t>(tbb::filter_mode::serial_in_order,
                                          [&](tbb::flow_control& fc) -> std::size_t {
                                            if (next >= groups.size()) fc.stop();
                                            return next++;
                                          }) &
          tbb::make_filter<std::size_t, std::vector<LayerOut>>(
              tbb::filter_mode::parallel, [&](std::size_t g) { return sample_group(groups[g]); }) &
          tbb::make_filter<std::vector<LayerOut>, void>(tbb::filter_mode::serial_in_order, [&](std::vector<LayerOut> outs) {
            for (LayerOut& out : outs) {
              const std::string name = cfg.slice_name(out.layer);
              io::write_file_atomically(opt.out_dir / name, out.png, io::Durability::deferred);
              finished[out.layer] = ManifestLayer{out.layer, name, out.sha256, out.counts, out.failures};
              unjournaled.push_back(finished[out.layer]);
              ++done;
              if (std::chrono::duration<double>(Clock::now() - last_manifest).count() >= opt.manifest_interval_s) {
                write_manifest_behind();
              }
              if (progress)
                progress(done, total_layers, static_cast<std::int64_t>(done) * grid.voxels_per_layer(),
                         std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
            }
          }));
  });

  const double pipeline_seconds = std::chrono::duration<double>(Clock::now() - pipeline_t0).count();
  if (pending_manifest.valid()) pending_manifest.get();  // before the whole manifest replaces the journal
  std::vector<std::int64_t> totals(static_cast<std::size_t>(nmat), 0);
  std::int64_t failures = 0;
  for (const auto& [k, l] : finished) {
    for (int m = 0; m < nmat; ++m) totals[static_cast<std::size_t>(m)] += l.voxels[static_cast<std::size_t>(m)];
    failures += l.failures;
  }
  SliceJobSummary sum;
  sum.grid = grid;
  sum.voxels = static_cast<std::int64_t>(total_layers) * grid.voxels_per_layer();
  sum.inversion_failures = failures;
  sum.material_voxels = totals;
  sum.voxel_volume_mm3 = grid.pitch[0] * grid.pitch[1] * grid.pitch[2];
  sum.mapping = mapper.describe();
  sum.layers_kept = kept;
  sum.pipeline_seconds = pipeline_seconds;
  sum.layer_range = manifest.layer_range;
  sum.shard = opt.shard;
  sum.estimate = est;
  for (const Scratch& s : scratch)
    for (std::size_t i = 0; i < s.seconds.size(); ++i) sum.stage_seconds[i] += s.seconds[i];
  for (int m = 0; m < nmat; ++m) {
    const auto& mat = palette.materials[static_cast<std::size_t>(m)];
    sum.materials.push_back(mat.name);
    sum.colours.push_back(mat.rgba);
    sum.filled += totals[static_cast<std::size_t>(m)];
  }
  cfg = stack_config_of(manifest, totals);
  // The archive's boundary mesh (archive_mesh.hpp): written by the whole job, or by shard 0 for
  // merge to pack; kept when a resumed job's manifest lists it and its bytes verify. A model
  // that cannot be meshed gives an archive without it and a warning.
  std::vector<std::string> zip_extra;
  std::optional<ManifestFile> mesh_entry;  // listed after ConfigFile.xml, as merge lists it
  if (opt.zip && opt.shard.index == 0) {
    const fs::path path = opt.out_dir / archive_mesh_name;
    const ManifestFile* kept_mesh = nullptr;
    if (previous)
      for (const ManifestFile& f : previous->files)
        if (f.role == "mesh" && f.file == archive_mesh_name && io::sha256_regular_file(path) == f.sha256) kept_mesh = &f;
    if (kept_mesh) {
      mesh_entry = *kept_mesh;
      zip_extra.push_back(archive_mesh_name);
      sum.mesh_file = path;
    } else {
      const ArchiveMesh mesh = archive_mesh(model, opt.model_name);
      if (mesh.stl.empty()) {
        sum.mesh_warning = opt.model_name + ": no " + archive_mesh_name + " in the archive: " + mesh.problem;
      } else {
        io::write_file_atomically(path, mesh.stl);
        mesh_entry = ManifestFile{"mesh", archive_mesh_name, io::sha256_hex(mesh.stl)};
        zip_extra.push_back(archive_mesh_name);
        sum.mesh_file = path;
        sum.mesh_triangles = mesh.triangles;
      }
    }
  }
  if (opt.shard.count == 1) {
    // The configuration that makes the folder a complete stack, once every layer is on disk.
    io::sync_folder_contents(opt.out_dir);
    const std::string config = io::config_xml(cfg);
    io::write_file_atomically(opt.out_dir / "ConfigFile.xml", config);
    manifest.files.push_back({"config", "ConfigFile.xml", io::sha256_hex(config)});
    if (mesh_entry) manifest.files.push_back(*mesh_entry);
    if (opt.zip) {
      const fs::path zip = io::gcvf_path(opt.out_dir);
      io::zip_stack(opt.out_dir, zip, zip_extra);
      sum.zip_file = zip;
      manifest.files.push_back({"zip", "../" + zip.filename().string(), io::sha256_file(zip)});
    }
  } else if (mesh_entry) {
    manifest.files.push_back(*mesh_entry);
  }
  write_manifest(opt.last_output);
  end_journal();
  sum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return sum;
}

void finish_manifest(const fs::path& dir, const Shard& shard, const std::vector<ManifestFile>& files) {
  auto m = read_manifest(dir, shard.manifest_name());
  if (!m)
    throw Error((dir / shard.manifest_name()).string() + ": missing; expected the manifest of the job being finished");
  for (const auto& f : files) {
    std::erase_if(m->files, [&](const ManifestFile& g) { return g.role == f.role; });
    m->files.push_back(f);
  }
  m->complete = true;
  io::write_file_atomically(dir / shard.manifest_name(), manifest_json(*m));
}

}  // namespace trivox::job
