#include "trivox/job/vdb_job.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <optional>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <system_error>

#include "thread_time.hpp"
#include "trivox/byte_size.hpp"
#include "trivox/error.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/io/sha256.hpp"
#include "trivox/io/vdb_color.hpp"
#include "trivox/io/vdb_volume.hpp"
#include "trivox/slice/locator.hpp"
#include "trivox/slice/material.hpp"
#include "trivox/slice/sampler.hpp"
#include "trivox/version.hpp"

namespace trivox::job {

namespace fs = std::filesystem;

namespace {

using detail::thread_cpu_seconds;

constexpr int leaf_dim = io::vdb_leaf_dim;       // the VDB's leaves are 8^3 voxels
constexpr double max_axis = 1073741824.0;        // 2^30 sub-samples along an axis
constexpr std::int64_t task_voxels = 1 << 18;    // voxels of one task (dense sums)
constexpr std::int64_t task_samples = 1 << 22;   // sub-samples of one task
constexpr int sample_rows = 32;                  // fine rows per sampler call (multiple of 4)
/// The smallest voxel edge, in the file's unit, that OpenVDB takes: its scale maps refuse a
/// transform whose determinant (edge^3) is under 3e-15 ("Non-zero scale values required",
/// openvdb/math/Maps.h, ScaleMap), i.e. an edge under cbrt(3e-15) = 1.44e-5.
const double min_scale = std::cbrt(3e-15) * (1 + 1e-12);

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

/// The smallest d x 10^e (d with two significant digits) >= v.
double round_up_2_digits(double v) {
  const int e = static_cast<int>(std::floor(std::log10(v))) - 1;
  const double scale = std::pow(10.0, std::abs(e));
  double m = std::ceil(e < 0 ? v * scale * (1 - 1e-12) : v / scale * (1 - 1e-12));
  auto value = [&](double mm) { return e < 0 ? mm / scale : mm * scale; };
  while (value(m) < v) m += 1.0;
  return value(m);
}

/// The folder: created, or (when asked) empty unless force; writable.
void prepare_folder(const fs::path& dir, bool require_empty, bool force) {
  std::error_code ec;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec))
      throw Error(dir.string() + ": exists and is not a folder; expected a new or empty folder for the output");
    if (require_empty && !force && fs::directory_iterator(dir, ec) != fs::directory_iterator())
      throw Error(dir.string() + ": the folder is not empty; expected a new or empty folder (or --force to overwrite)");
  } else if (!fs::create_directories(dir, ec) || ec) {
    throw Error(dir.string() + ": cannot create the folder (" + ec.message() + "); expected a writable location");
  }
  const fs::path probe = dir / ".trivox-write-test";
  try {
    io::write_file_atomically(probe, "");
  } catch (const Error&) {
    throw Error(dir.string() + ": the folder is not writable; expected a writable folder");
  }
  fs::remove(probe, ec);
}

/// World units (the transform's) per model millimetre divisor: mm 1, m 1000.
double unit_mm(VdbUnits u) { return u == VdbUnits::m ? 1000.0 : 1.0; }

/// Grid names that Blender or Houdini read with a meaning of their own (Blender's volume
/// attributes density, color, temperature, flame, heat; Houdini's density, Cd, temperature,
/// heat, flame): a model property never takes one of them (docs/vdb.md, "Names").
bool reserved_name(const std::string& n) {
  for (const char* r : {"density", "color", "Cd", "temperature", "heat", "flame"})
    if (n == r) return true;
  return false;
}

/// What the grids are made of: names, and which properties feed which grid.
struct Layout {
  int nprops = 0, nmat = 0;
  bool rgb = false;
  bool linear = false;                      // color holds linear RGB (VdbColorSpace::linear)
  int ncolor = 0;                           // 3 when the r, g, b sums are decoded per sample, else 0
  std::array<int, 3> rgb_props{};           // indices of r, g, b
  std::vector<int> extra_props;             // properties with a grid of their own
  std::vector<std::string> extra_names;     // their grid names
  std::vector<std::array<float, 3>> material_rgb;  // palette RGB / 255, decoded to linear when linear
};

Layout make_layout(const vmodel::VModel& model, const slice::Palette& palette, VdbColorSpace space) {
  Layout l;
  l.nprops = static_cast<int>(model.properties.size());
  l.nmat = static_cast<int>(palette.materials.size());
  std::array<int, 3> found{-1, -1, -1};
  for (int p = 0; p < l.nprops; ++p) {
    const std::string& n = model.properties[static_cast<std::size_t>(p)];
    if (n == "r") found[0] = p;
    if (n == "g") found[1] = p;
    if (n == "b") found[2] = p;
  }
  l.rgb = found[0] >= 0 && found[1] >= 0 && found[2] >= 0;
  if (l.rgb) l.rgb_props = found;
  for (int p = 0; p < l.nprops; ++p) {
    const std::string& n = model.properties[static_cast<std::size_t>(p)];
    if (l.rgb && (p == found[0] || p == found[1] || p == found[2])) continue;
    if (palette.find(n) >= 0) continue;
    const bool taken = reserved_name(n) || n.rfind("material.", 0) == 0 || n.rfind("property.", 0) == 0;
    l.extra_props.push_back(p);
    l.extra_names.push_back(taken ? "property." + n : n);
  }
  l.linear = space == VdbColorSpace::linear;
  l.ncolor = l.rgb && l.linear ? 3 : 0;
  for (const auto& m : palette.materials) {
    if (l.linear) {  // decoded first, so that mixing by fractions mixes light
      std::array<float, 3> c{};
      for (std::size_t q = 0; q < 3; ++q) c[q] = static_cast<float>(io::srgb_to_linear(m.rgba[q] / 255.0));
      l.material_rgb.push_back(c);
    } else {
      l.material_rgb.push_back({m.rgba[0] / 255.0f, m.rgba[1] / 255.0f, m.rgba[2] / 255.0f});
    }
  }
  return l;
}

/// The VDB file's grids and metadata (docs/vdb.md): voxel (i, j, k) centred at origin + (ijk + 1/2)
/// voxel; one float grid per palette material, then one per other property.
/// World coordinates are millimetres, or metres (every length divided by 1000).
io::VdbVolumeSpec volume_spec(const vmodel::VModel& model, const VdbPlan& plan, const slice::Palette& palette,
                              const Layout& layout, const VdbJobOptions& opt, const std::string& model_sha) {
  const double vx = plan.voxel_mm, unit = unit_mm(opt.units);
  const fs::path& model_file = opt.model_file;
  io::VdbVolumeSpec spec;
  // mm: as before, with no division (the same bytes as files written before the option).
  spec.voxel_size = opt.units == VdbUnits::mm ? vx : vx / unit;
  for (std::size_t d = 0; d < 3; ++d)
    spec.first_centre[d] = opt.units == VdbUnits::mm ? plan.origin[d] + vx / 2 : (plan.origin[d] + vx / 2) / unit;
  spec.metadata = {
      {"units", std::string(vdb_units_name(opt.units))},
      {"generator", std::string("trivox ") + trivox::version},
      {"source", model_file.filename().string()},
      {"source_sha256", model_sha},
      {"voxel_size", spec.voxel_size},
      {"supersample", std::int32_t{plan.supersample}},
      {"palette", palette.name},
      {"palette_sha256", io::sha256_hex(slice::palette_json(palette))},
      {"colour_source", std::string(layout.rgb ? "r,g,b" : "palette")},
      {"color_space", std::string(vdb_color_space_name(opt.color_space))},
  };
  for (const auto& mat : palette.materials)
    spec.float_grids.push_back({"material." + mat.name,
                                {{"material", mat.name},
                                 {"rgba", std::to_string(mat.rgba[0]) + " " + std::to_string(mat.rgba[1]) + " " +
                                              std::to_string(mat.rgba[2]) + " " + std::to_string(mat.rgba[3])}}});
  for (std::size_t e = 0; e < layout.extra_props.size(); ++e)
    spec.float_grids.push_back(
        {layout.extra_names[e], {{"property", model.properties[static_cast<std::size_t>(layout.extra_props[e])]}}});
  return spec;
}

/// One task's output: its leaves (disjoint from every other task's), built in the parallel stage,
/// and sums.
struct TaskOut {
  explicit TaskOut(int float_grids) : leaves(float_grids) {}
  io::VdbLeaves leaves;
  std::int64_t active = 0, fractional = 0, failures = 0, samples = 0;
  double density_sum = 0.0;               // sum of density
  std::vector<double> material_sum;       // sum of fraction x density
};

/// Per-worker scratch, reused across tasks.
struct Scratch {
  slice::RowBand band;
  std::vector<std::int32_t> count;   // inside sub-samples per voxel
  std::vector<double> sums;          // per voxel: nprops property sums, then nmat fraction sums
  std::vector<float> fractions;
  io::VdbLeafValues leaf;            // one leaf's values
};

}  // namespace

bool vdb_units_from_name(std::string_view name, VdbUnits& out) noexcept {
  if (name == "mm") out = VdbUnits::mm;
  else if (name == "m") out = VdbUnits::m;
  else return false;
  return true;
}

const char* vdb_units_name(VdbUnits units) noexcept { return units == VdbUnits::m ? "m" : "mm"; }

bool vdb_color_space_from_name(std::string_view name, VdbColorSpace& out) noexcept {
  if (name == "linear") out = VdbColorSpace::linear;
  else if (name == "srgb") out = VdbColorSpace::srgb;
  else return false;
  return true;
}

const char* vdb_color_space_name(VdbColorSpace space) noexcept {
  return space == VdbColorSpace::srgb ? "srgb" : "linear";
}

namespace {
/// The memory model of VdbPlan::estimated_memory_bytes (calibrated on the twisted column's
/// default job: 48.8 M active voxels of 10 values peaked at 2.25 GB; the model gives 2.49 GB).
constexpr double memory_base = 150e6;      // the model, its locator, the process
constexpr double leaf_overhead = 1.2;      // leaves store inactive values near the surface too
}  // namespace

VdbPlan plan_vdb_job(const vmodel::VModel& model, const VdbJobOptions& opt) {
  if (model.cells.empty())
    throw Error((opt.model_file.empty() ? std::string("the model") : opt.model_file.string()) +
                ": no cells; expected at least one volumetric cell (a trivariate) to sample");
  if (opt.supersample < 1 || opt.supersample > 8)
    throw Error("--supersample " + std::to_string(opt.supersample) + ": out of range; expected 1 to 8 (N^3 samples per voxel)");
  if (opt.voxel_mm && !(std::isfinite(*opt.voxel_mm) && *opt.voxel_mm > 0.0))
    throw Error("--vdb-voxel " + num(*opt.voxel_mm) + ": not a positive size; expected a voxel edge in mm, above 0");
  VdbPlan plan;
  plan.supersample = opt.supersample;
  const auto box = opt.model_box ? *opt.model_box : slice::model_bounds(model);
  slice::check_solid_box(box[0], box[1], opt.model_file.empty() ? std::string("the model") : opt.model_file.string());
  plan.origin = box[0];
  plan.model_box = box;

  if (opt.model_volume_mm3) {
    plan.estimated_volume_mm3 = *opt.model_volume_mm3;
  } else {
    std::vector<double> volumes(model.cells.size());
    tbb::parallel_for(std::size_t{0}, model.cells.size(),
                      [&](std::size_t i) { volumes[i] = std::abs(geom::signed_volume(model.cells[i].volume)); });
    for (double v : volumes) plan.estimated_volume_mm3 += v;
  }

  std::array<double, 3> extent{};
  double box_volume = 1.0;
  for (std::size_t d = 0; d < 3; ++d) {
    extent[d] = box[1][d] - box[0][d];
    box_volume *= std::max(extent[d], 0.0);
  }
  // Memory: the values of the grids per active voxel, and each worker's task sums.
  {
    const slice::Palette palette = opt.palette ? slice::load_palette(*opt.palette) : slice::default_palette();
    const Layout layout = make_layout(model, palette, opt.color_space);
    plan.grids_values = 1 + 3 + layout.nmat + static_cast<int>(layout.extra_props.size());
  }
  const double bytes_per_active = 4.0 * plan.grids_values * leaf_overhead;
  const double workers = static_cast<double>(tbb::this_task_arena::max_concurrency()) *
                         static_cast<double>(task_voxels) * (plan.grids_values + 4) * 8.0;
  const double room = static_cast<double>(opt.max_memory_bytes) - memory_base - workers;
  if (!(room > 0.0))
    throw Error("--max-memory " + memory_size_text(static_cast<double>(opt.max_memory_bytes)) + ": below what any VDB job needs (" +
                memory_size_text(memory_base + workers) + " before its grids); expected more memory");
  if (opt.voxel_mm) {
    plan.voxel_mm = *opt.voxel_mm;
  } else {
    plan.automatic = true;
    const double by_volume = std::cbrt(plan.estimated_volume_mm3 / static_cast<double>(opt.target_active_voxels));
    const double by_box = std::cbrt(box_volume / static_cast<double>(opt.max_dense_voxels));
    const double by_memory = std::cbrt(plan.estimated_volume_mm3 * bytes_per_active / room);
    double v = std::max({by_volume, by_box, by_memory});
    if (!(v > 0.0) || !std::isfinite(v)) v = std::max({extent[0], extent[1], extent[2], 1e-3}) / 64.0;
    plan.voxel_mm = round_up_2_digits(v);
  }
  const double vx = plan.voxel_mm;
  if (vx / unit_mm(opt.units) < min_scale)
    throw Error("--vdb-voxel " + num(vx) + ": a voxel of " + num(vx / unit_mm(opt.units)) + " " +
                vdb_units_name(opt.units) + "; expected at least " + num(min_scale * unit_mm(opt.units)) +
                " mm, the smallest voxel OpenVDB's transforms take in " + vdb_units_name(opt.units) +
                (opt.units == VdbUnits::m ? " (or --vdb-units mm, which takes voxels down to 1.45e-05 mm)" : ""));
  double dense = 1.0;
  static constexpr const char* axis = "xyz";
  for (std::size_t d = 0; d < 3; ++d) {
    const double n = std::max(1.0, std::ceil(extent[d] / vx));
    if (n * opt.supersample > max_axis)
      throw Error("--vdb-voxel " + num(vx) + ": " + num(n) + " voxels along " + axis[d] + " (" + num(extent[d]) +
                  " mm) with --supersample " + std::to_string(opt.supersample) + "; expected at most " +
                  num(max_axis) + " sub-samples along an axis");
    plan.count[d] = static_cast<int>(n);
    dense *= n;
  }
  plan.dense_voxels = static_cast<std::int64_t>(dense);
  plan.estimated_active_voxels = plan.estimated_volume_mm3 / (vx * vx * vx);
  if (dense > static_cast<double>(opt.max_dense_voxels) && !opt.force)
    throw Error("--vdb-voxel " + num(vx) + ": the box " + num(extent[0]) + " x " + num(extent[1]) + " x " +
                num(extent[2]) + " mm needs " + std::to_string(plan.count[0]) + " x " + std::to_string(plan.count[1]) +
                " x " + std::to_string(plan.count[2]) + " = " + num(dense) + " voxels; expected at most " +
                num(static_cast<double>(opt.max_dense_voxels)) + " (a larger --vdb-voxel, or --force)");
  // A shard holds its layers' share.
  const double share =
      opt.layer_range ? std::clamp(static_cast<double>((*opt.layer_range)[1] - (*opt.layer_range)[0]) / plan.count[2], 0.0, 1.0)
                      : 1.0;
  plan.estimated_memory_bytes = memory_base + workers + plan.estimated_active_voxels * share * bytes_per_active;
  if (plan.estimated_memory_bytes > static_cast<double>(opt.max_memory_bytes))
    throw Error("--vdb-voxel " + num(vx) + ": about " + num(plan.estimated_active_voxels * share) + " active voxels of " +
                std::to_string(plan.grids_values) + " values each, an estimated " + memory_size_text(plan.estimated_memory_bytes) +
                " of memory; expected at most " + memory_size_text(static_cast<double>(opt.max_memory_bytes)) +
                " (raise --max-memory, or a larger --vdb-voxel)");
  if (opt.layer_range) {
    const auto [first, end] = *opt.layer_range;
    const int nz = plan.count[2];
    if (first < 0 || first > end || end > nz || first % leaf_dim != 0 || (end % leaf_dim != 0 && end != nz))
      throw Error("VDB layer range [" + std::to_string(first) + ", " + std::to_string(end) + ") of " +
                  std::to_string(nz) + " layers; expected whole blocks of 8 layers (the end may be the last layer)");
  }
  const std::string stem = opt.model_file.empty() ? std::string("model") : opt.model_file.stem().string();
  plan.file = opt.out_dir / (!opt.file_name.empty() ? opt.file_name : stem.empty() ? std::string("model.vdb") : stem + ".vdb");
  return plan;
}

VdbJobSummary run_vdb_job(const vmodel::VModel& model, const VdbJobOptions& opt, const VdbProgress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const VdbPlan plan = plan_vdb_job(model, opt);
  const slice::Palette palette = opt.palette ? slice::load_palette(*opt.palette) : slice::default_palette();
  const slice::MaterialMapper mapper(palette, model.properties, opt.palette ? opt.palette->string() : std::string());
  const Layout layout = make_layout(model, palette, opt.color_space);
  const std::string model_sha =
      !opt.model_sha256.empty() ? opt.model_sha256 : opt.model_file.empty() ? std::string() : io::sha256_file(opt.model_file);
  // The grids, filled with the tasks' leaves in task order (none in a dry run).
  std::optional<io::VdbVolume> volume;
  if (!opt.dry_run) {
    prepare_folder(opt.out_dir, opt.require_empty_folder, opt.force);
    volume.emplace(volume_spec(model, plan, palette, layout, opt, model_sha));
  }

  const int N = plan.supersample;
  const int nx = plan.count[0], ny = plan.count[1], nz = plan.count[2];
  const int ny_pad = (ny + leaf_dim - 1) / leaf_dim * leaf_dim;
  const double vx = plan.voxel_mm;

  // The fine grid: its voxel centres are the sub-samples. Rows padded to whole leaves in y, so
  // every task's rows start on a block of the sampler (LayerSampler::block_rows).
  slice::VoxelGrid fine;
  fine.origin = plan.origin;
  fine.pitch = {vx / N, vx / N, vx / N};
  fine.count = {nx * N, ny_pad * N, nz * N};
  const slice::LayerSampler sampler(model, fine, opt.sampler);
  const int nyf = fine.count[1];

  // Tasks: 8 layers (one leaf) in z by `band` rows (whole leaves) in y, every column.
  const std::int64_t n3 = static_cast<std::int64_t>(N) * N * N;
  const std::int64_t per_leaf_row = static_cast<std::int64_t>(leaf_dim) * leaf_dim * nx;  // voxels of 8 x 8 rows
  const std::int64_t leaves_y =
      std::max<std::int64_t>(1, std::min(task_voxels / per_leaf_row, task_samples / (per_leaf_row * n3)));
  const int band = static_cast<int>(std::min<std::int64_t>(leaves_y * leaf_dim, ny_pad));
  const int bands = (ny + band - 1) / band;
  const int slab0 = opt.layer_range ? (*opt.layer_range)[0] / leaf_dim : 0;
  const int slab1 = opt.layer_range ? ((*opt.layer_range)[1] + leaf_dim - 1) / leaf_dim : (nz + leaf_dim - 1) / leaf_dim;
  const int tasks = bands * (slab1 - slab0);
  const int P = layout.nprops, M = layout.nmat;
  const int C = layout.ncolor;  // decoded r, g, b after the fractions (linear colour from r, g, b)
  const int channels = P + M + C;
  const float inv_n3 = 1.0f / static_cast<float>(n3);

  tbb::enumerable_thread_specific<Scratch> scratch;

  auto run_task = [&](int t) {
    TaskOut out(M + static_cast<int>(layout.extra_props.size()));
    out.material_sum.assign(static_cast<std::size_t>(M), 0.0);
    const int k0 = (slab0 + t / bands) * leaf_dim, k1 = std::min(k0 + leaf_dim, nz);
    const int j0 = (t % bands) * band, j1 = std::min(j0 + band, ny);
    const int nk = k1 - k0, nj = j1 - j0;
    Scratch& s = scratch.local();
    const std::size_t voxels = static_cast<std::size_t>(nk) * static_cast<std::size_t>(nj) * static_cast<std::size_t>(nx);
    // Only the counts are cleared: a voxel's sums are set by its first sample (as 0 + value, the
    // floats of clearing and adding) and read only where its count is positive, so the sums of
    // void voxels (most of a box) cost nothing.
    s.count.assign(voxels, 0);
    s.sums.resize(voxels * static_cast<std::size_t>(channels));
    s.fractions.resize(static_cast<std::size_t>(M));
    // Fine rows of grid rows [j0 N, j1 N) are image rows [nyf - j1 N, nyf - j0 N) (grid.hpp).
    // The last band samples up to the padded row count, so its first row stays block-aligned;
    // the padding rows lie outside the model's box (void) and are skipped.
    const int j1_pad = std::min(j0 + band, ny_pad);
    const int r_begin = nyf - j1_pad * N, r_end = nyf - j0 * N;
    for (int kf = k0 * N; kf < k1 * N; ++kf) {
      const std::size_t kk = static_cast<std::size_t>(kf / N - k0);
      for (int r0 = r_begin; r0 < r_end; r0 += sample_rows) {
        const int rows = std::min(sample_rows, r_end - r0);
        sampler.sample(kf, r0, rows, s.band);
        out.failures += s.band.failures;
        for (int r = 0; r < rows; ++r) {
          const int jf = nyf - 1 - (r0 + r);
          if (jf / N >= j1) continue;
          const std::size_t jj = static_cast<std::size_t>(jf / N - j0);
          const std::size_t row = (kk * static_cast<std::size_t>(nj) + jj) * static_cast<std::size_t>(nx);
          for (int i_f = 0; i_f < nx * N; ++i_f) {
            if (s.band.cell_at(r, i_f) < 0) continue;
            const std::size_t v = row + static_cast<std::size_t>(i_f / N);
            const bool first = s.count[v]++ == 0;
            const float* p = s.band.props_at(r, i_f);
            double* acc = s.sums.data() + v * static_cast<std::size_t>(channels);
            for (int h = 0; h < P; ++h) acc[h] = (first ? 0.0 : acc[h]) + p[h];
            mapper.fractions(p, s.fractions.data());
            for (int m = 0; m < M; ++m) acc[P + m] = (first ? 0.0 : acc[P + m]) + s.fractions[static_cast<std::size_t>(m)];
            // Linear colour from r, g, b: each sample decoded, then averaged (mixing light).
            for (int q = 0; q < C; ++q)
              acc[P + M + q] = (first ? 0.0 : acc[P + M + q]) +
                               io::srgb_to_linear(std::clamp(p[layout.rgb_props[static_cast<std::size_t>(q)]], 0.0f, 1.0f));
          }
        }
      }
    }
    out.samples = static_cast<std::int64_t>(voxels) * n3;

    // Leaves, one 8^3 block at a time, every grid with the same active voxels.
    const int E = static_cast<int>(layout.extra_props.size());
    std::vector<float> mean(static_cast<std::size_t>(channels));
    io::VdbLeafValues& leaf = s.leaf;
    for (int bj = j0; bj < j1; bj += leaf_dim)
      for (int bi = 0; bi < nx; bi += leaf_dim) {
        const int ei = std::min(bi + leaf_dim, nx), ej = std::min(bj + leaf_dim, j1);
        bool any = false;
        for (int k = 0; k < nk && !any; ++k)
          for (int j = bj; j < ej && !any; ++j)
            for (int i = bi; i < ei; ++i)
              if (s.count[(static_cast<std::size_t>(k) * nj + static_cast<std::size_t>(j - j0)) * nx + static_cast<std::size_t>(i)] > 0) {
                any = true;
                break;
              }
        if (!any) continue;
        leaf.clear({bi, bj, k0}, M + E);
        float* const mat_values = leaf.floats.data();
        float* const extra_values = mat_values + static_cast<std::size_t>(M) * io::vdb_leaf_voxels;
        for (int k = 0; k < nk; ++k)
          for (int j = bj; j < ej; ++j)
            for (int i = bi; i < ei; ++i) {
              const std::size_t v = (static_cast<std::size_t>(k) * nj + static_cast<std::size_t>(j - j0)) * nx + static_cast<std::size_t>(i);
              const std::int32_t c = s.count[v];
              if (c == 0) continue;
              const double* acc = s.sums.data() + v * static_cast<std::size_t>(channels);
              // One sample (every voxel without supersampling): its value, as acc / 1 would give.
              if (c == 1)
                for (int h = 0; h < channels; ++h) mean[static_cast<std::size_t>(h)] = static_cast<float>(acc[h]);
              else
                for (int h = 0; h < channels; ++h) mean[static_cast<std::size_t>(h)] = static_cast<float>(acc[h] / c);
              const float density = static_cast<float>(c) * inv_n3;
              const int off = io::VdbLeafValues::offset(i - bi, j - bj, k);
              const auto at = static_cast<std::size_t>(off);
              leaf.set_active(off);
              leaf.density[at] = density;
              ++out.active;
              if (c < n3) ++out.fractional;
              out.density_sum += density;
              std::array<float, 3> rgb{0.0f, 0.0f, 0.0f};
              if (C > 0) {
                for (int q = 0; q < 3; ++q)
                  rgb[static_cast<std::size_t>(q)] = std::clamp(mean[static_cast<std::size_t>(P + M + q)], 0.0f, 1.0f);
              } else if (layout.rgb) {
                for (int q = 0; q < 3; ++q)
                  rgb[static_cast<std::size_t>(q)] =
                      std::clamp(mean[static_cast<std::size_t>(layout.rgb_props[static_cast<std::size_t>(q)])], 0.0f, 1.0f);
              } else {
                for (int m = 0; m < M; ++m)
                  for (std::size_t q = 0; q < 3; ++q)
                    rgb[q] += mean[static_cast<std::size_t>(P + m)] * layout.material_rgb[static_cast<std::size_t>(m)][q];
                for (float& x : rgb) x = std::clamp(x, 0.0f, 1.0f);
              }
              for (std::size_t q = 0; q < 3; ++q) leaf.color[3 * at + q] = rgb[q];
              for (int m = 0; m < M; ++m) {
                const float f = mean[static_cast<std::size_t>(P + m)];
                mat_values[static_cast<std::size_t>(m) * io::vdb_leaf_voxels + at] = f;
                out.material_sum[static_cast<std::size_t>(m)] += static_cast<double>(f) * density;
              }
              for (int e = 0; e < E; ++e)
                extra_values[static_cast<std::size_t>(e) * io::vdb_leaf_voxels + at] =
                    mean[static_cast<std::size_t>(layout.extra_props[static_cast<std::size_t>(e)])];
            }
        out.leaves.add(leaf);
      }
    return out;
  };

  VdbJobSummary sum;
  sum.plan = plan;
  sum.tasks = tasks;
  sum.material_volume_mm3.assign(static_cast<std::size_t>(M), 0.0);
  const int threads = static_cast<int>(tbb::this_task_arena::max_concurrency());
  if (opt.dry_run) {
    // The time: 8 tasks evenly spread over the task order (which runs slab by slab up the
    // model) run in memory, their mean CPU time over the tasks.
    constexpr int probe_tasks = 8;
    std::vector<int> probe;
    for (int q = 0; q < probe_tasks; ++q)
      if (const int t = static_cast<int>(static_cast<std::int64_t>(tasks) * (2 * q + 1) / (2 * probe_tasks));
          t < tasks && (probe.empty() || probe.back() != t))
        probe.push_back(t);
    std::vector<double> cpu(probe.size());
    tbb::parallel_for(std::size_t{0}, probe.size(), [&](std::size_t i) {
      const double c0 = thread_cpu_seconds();
      (void)run_task(probe[i]);
      cpu[i] = thread_cpu_seconds() - c0;
    });
    double total = 0.0;
    for (double c : cpu) total += c;
    sum.dry_run = true;
    sum.timed_tasks = static_cast<int>(probe.size());
    sum.estimated_seconds = probe.empty() ? 0.0 : total / static_cast<double>(probe.size()) * tasks / threads;
    sum.file = plan.file;
    for (const auto& m : palette.materials) sum.materials.push_back(m.name);
    sum.palette = palette.name;
    sum.units = vdb_units_name(opt.units);
    sum.color_space = vdb_color_space_name(opt.color_space);
    sum.colour_source = layout.rgb ? "r,g,b" : "palette";
    sum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return sum;
  }
  double density_sum = 0.0;
  int done = 0, next = 0;
  const int tokens = threads + 1;
  tbb::parallel_pipeline(
      static_cast<std::size_t>(tokens),
      tbb::make_filter<void, int>(tbb::filter_mode::serial_in_order,
                                  [&](tbb::flow_control& fc) {
                                    if (next >= tasks) {
                                      fc.stop();
                                      return 0;
                                    }
                                    return next++;
                                  }) &
          tbb::make_filter<int, std::shared_ptr<TaskOut>>(
              tbb::filter_mode::parallel, [&](int t) { return std::make_shared<TaskOut>(run_task(t)); }) &
          tbb::make_filter<std::shared_ptr<TaskOut>, void>(tbb::filter_mode::serial_in_order, [&](std::shared_ptr<TaskOut> o) {
            // The grids take the leaves over (each is a new leaf position: tasks are disjoint).
            volume->adopt(o->leaves);
            sum.active_voxels += o->active;
            sum.fractional_voxels += o->fractional;
            sum.inversion_failures += o->failures;
            sum.samples += o->samples;
            density_sum += o->density_sum;
            for (int m = 0; m < M; ++m) sum.material_volume_mm3[static_cast<std::size_t>(m)] += o->material_sum[static_cast<std::size_t>(m)];
            ++done;
            if (progress)
              progress(done, tasks, sum.samples,
                       std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
          }));

  const double voxel_volume = vx * vx * vx;
  sum.volume_mm3 = density_sum * voxel_volume;
  for (double& v : sum.material_volume_mm3) v *= voxel_volume;

  const auto [bytes, digest] = volume->write(plan.file);
  sum.grids = volume->grid_names();

  sum.file = plan.file;
  sum.materials.reserve(static_cast<std::size_t>(M));
  for (const auto& m : palette.materials) sum.materials.push_back(m.name);
  sum.colour_source = layout.rgb ? "r,g,b" : "palette";
  sum.units = vdb_units_name(opt.units);
  sum.color_space = vdb_color_space_name(opt.color_space);
  sum.palette = palette.name;
  sum.sha256 = digest;
  sum.bytes = bytes;
  sum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return sum;
}

}  // namespace trivox::job
