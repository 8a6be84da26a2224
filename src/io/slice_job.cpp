#include "trivox/io/slice_job.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <system_error>

#include "trivox/error.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/io/slice_stack.hpp"
#include "trivox/slice/dither.hpp"
#include "trivox/slice/material.hpp"
#include "trivox/slice/sampler.hpp"

namespace trivox::io {

namespace fs = std::filesystem;

namespace {

std::string human_bytes(double b) {
  const char* units[] = {"B", "KB", "MB", "GB", "TB", "PB"};
  int u = 0;
  while (b >= 1000.0 && u < 5) b /= 1000.0, ++u;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g %s", b, units[u]);
  return buf;
}

void check_profile(const slice::PrintProfile& p) {
  if (!(std::isfinite(p.dpi_x) && std::isfinite(p.dpi_y) && p.dpi_x >= 10 && p.dpi_x <= 10000 && p.dpi_y >= 10 &&
        p.dpi_y <= 10000))
    throw Error("--dpi " + std::to_string(p.dpi_x) + "," + std::to_string(p.dpi_y) +
                ": out of range; expected 10 to 10000 dots per inch in x and y");
  if (!(std::isfinite(p.layer_mm) && p.layer_mm >= 0.001 && p.layer_mm <= 10.0))
    throw Error("--layer " + std::to_string(p.layer_mm) + ": out of range; expected a layer of 0.001 to 10 mm");
}

/// The output folder: created, or empty, or --force.
void prepare_folder(const fs::path& dir, bool force) {
  std::error_code ec;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec))
      throw Error(dir.string() + ": exists and is not a folder; expected a new or empty folder for the slices");
    if (!force && fs::directory_iterator(dir, ec) != fs::directory_iterator())
      throw Error(dir.string() + ": the folder is not empty; expected a new or empty folder (or --force to overwrite)");
  } else if (!fs::create_directories(dir, ec) || ec) {
    throw Error(dir.string() + ": cannot create the folder (" + ec.message() + "); expected a writable location");
  }
  // Probe writability now rather than after the first layer.
  const fs::path probe = dir / ".trivox-write-test";
  try {
    write_file_atomically(probe, "");
  } catch (const Error& e) {
    throw Error(dir.string() + ": the folder is not writable; expected a writable folder");
  }
  fs::remove(probe, ec);
}

/// Per-worker scratch, reused across layers so a job allocates once per thread.
struct Scratch {
  slice::RowBand band;
  std::vector<float> fractions;
  std::vector<std::uint8_t> chosen;
  std::vector<std::uint8_t> rgba;
};

/// One layer on its way through the pipeline.
struct LayerOut {
  int layer = -1;
  std::string png;
  std::vector<std::int64_t> counts;
  std::int64_t failures = 0;
};

}  // namespace

slice::VoxelGrid slice_grid(const vmodel::VModel& model, const slice::PrintProfile& profile) {
  if (model.cells.empty())
    throw Error("the model has no cells; expected at least one volumetric cell to slice");
  check_profile(profile);
  const auto box = slice::model_bounds(model);
  return slice::VoxelGrid::covering(box[0], box[1], {profile.pitch_x(), profile.pitch_y(), profile.pitch_z()});
}

SliceJobSummary run_slice_job(const vmodel::VModel& model, const SliceJobOptions& opt, const SliceProgress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const slice::VoxelGrid grid = slice_grid(model, opt.profile);
  const auto box = slice::model_bounds(model);

  // Size checks before anything is written.
  const double bytes = static_cast<double>(grid.voxels()) * 4.0;
  const std::string estimate = std::to_string(grid.count[0]) + " x " + std::to_string(grid.count[1]) + " x " +
                               std::to_string(grid.count[2]) + " = " + std::to_string(grid.voxels()) + " voxels, " +
                               human_bytes(bytes) + " of RGBA pixels before compression";
  if (!opt.force) {
    static constexpr const char* axis = "xyz";
    for (int d = 0; d < 3; ++d) {
      const auto dd = static_cast<std::size_t>(d);
      if (box[1][dd] - box[0][dd] > opt.profile.tray_mm[dd])
        throw Error(opt.model_name + ": the model is " + std::to_string(box[1][dd] - box[0][dd]) + " mm along " + axis[d] +
                    ", larger than the " + opt.profile.name + " tray (" + std::to_string(opt.profile.tray_mm[dd]) +
                    " mm); expected a model that fits (or --force). Job: " + estimate);
    }
    if (grid.voxels() > opt.max_voxels)
      throw Error(opt.model_name + ": the job has " + estimate + "; expected at most " + std::to_string(opt.max_voxels) +
                  " voxels (raise --max-voxels or use --force)");
  }

  const slice::Palette palette = opt.palette ? slice::load_palette(*opt.palette) : slice::default_palette();
  const slice::MaterialMapper mapper(palette, model.properties);
  const slice::DitherMode mode = slice::parse_dither_mode(opt.dither);
  prepare_folder(opt.out_dir, opt.force);

  const slice::LayerSampler sampler(model, grid);
  const int nx = grid.count[0], ny = grid.count[1], nz = grid.count[2];
  const int nmat = mapper.materials();
  const int nprops = static_cast<int>(model.properties.size());
  const int band_rows = std::max(1, std::min(opt.band_rows, ny));

  StackConfig cfg;
  cfg.dpi_x = opt.profile.dpi_x;
  cfg.dpi_y = opt.profile.dpi_y;
  cfg.slice_thickness_nm = opt.profile.layer_mm * 1e6;
  cfg.width = nx;
  cfg.height = ny;
  cfg.slices = nz;
  cfg.digits = std::max(5, static_cast<int>(std::to_string(nz).size()));

  tbb::enumerable_thread_specific<Scratch> scratch;
  std::vector<std::int64_t> totals(static_cast<std::size_t>(nmat), 0);
  std::int64_t failures = 0;
  int done = 0;
  const int tokens = static_cast<int>(tbb::this_task_arena::max_concurrency()) + 1;
  int next = 0;

  auto sample_layer = [&](int k) {
    LayerOut out;
    out.layer = k;
    out.counts.assign(static_cast<std::size_t>(nmat), 0);
    Scratch& s = scratch.local();
    s.rgba.assign(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) * 4, 0);
    slice::LayerDitherer dither(mode, nx, nmat, grid.pitch[0], grid.pitch[1]);
    dither.begin_layer(k);
    for (int r0 = 0; r0 < ny; r0 += band_rows) {
      const int rows = std::min(band_rows, ny - r0);
      sampler.sample(k, r0, rows, s.band);
      out.failures += s.band.failures;
      const std::size_t n = static_cast<std::size_t>(rows) * static_cast<std::size_t>(nx);
      s.fractions.resize(n * static_cast<std::size_t>(nmat));
      s.chosen.resize(n);
      for (std::size_t v = 0; v < n; ++v)
        if (s.band.cell[v] >= 0)
          mapper.fractions(s.band.props.data() + v * static_cast<std::size_t>(nprops),
                           s.fractions.data() + v * static_cast<std::size_t>(nmat));
      dither.dither(r0, rows, s.band.cell.data(), s.fractions.data(), s.chosen.data());
      std::uint8_t* px = s.rgba.data() + static_cast<std::size_t>(r0) * static_cast<std::size_t>(nx) * 4;
      for (std::size_t v = 0; v < n; ++v) {
        const std::uint8_t m = s.chosen[v];
        if (m == 255) continue;  // void stays transparent 0 0 0 0
        const auto& c = palette.materials[m].rgba;
        px[4 * v + 0] = c[0];
        px[4 * v + 1] = c[1];
        px[4 * v + 2] = c[2];
        px[4 * v + 3] = c[3];
        ++out.counts[m];
      }
    }
    out.png = encode_png_rgba(s.rgba.data(), nx, ny, cfg.dpi_x, cfg.dpi_y);
    return out;
  };

  tbb::parallel_pipeline(
      static_cast<std::size_t>(tokens),
      tbb::make_filter<void, int>(tbb::filter_mode::serial_in_order,
                                  [&](tbb::flow_control& fc) {
                                    if (next >= nz) {
                                      fc.stop();
                                      return 0;
                                    }
                                    return next++;
                                  }) &
          tbb::make_filter<int, LayerOut>(tbb::filter_mode::parallel, sample_layer) &
          tbb::make_filter<LayerOut, void>(tbb::filter_mode::serial_in_order, [&](LayerOut out) {
            write_file_atomically(opt.out_dir / cfg.slice_name(out.layer), out.png);
            for (int m = 0; m < nmat; ++m) totals[static_cast<std::size_t>(m)] += out.counts[static_cast<std::size_t>(m)];
            failures += out.failures;
            ++done;
            if (progress)
              progress(done, nz, static_cast<std::int64_t>(done) * grid.voxels_per_layer(),
                       std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
          }));

  SliceJobSummary sum;
  sum.grid = grid;
  sum.voxels = grid.voxels();
  sum.inversion_failures = failures;
  sum.material_voxels = totals;
  sum.voxel_volume_mm3 = grid.pitch[0] * grid.pitch[1] * grid.pitch[2];
  sum.mapping = mapper.describe();
  for (int m = 0; m < nmat; ++m) {
    const auto& mat = palette.materials[static_cast<std::size_t>(m)];
    sum.materials.push_back(mat.name);
    sum.colours.push_back(mat.rgba);
    sum.filled += totals[static_cast<std::size_t>(m)];
    cfg.materials.push_back({mat.name, mat.rgba, totals[static_cast<std::size_t>(m)]});
  }
  // Last: the configuration that makes the folder a complete stack.
  write_file_atomically(opt.out_dir / "ConfigFile.xml", config_xml(cfg));
  if (opt.zip) {
    fs::path zip = opt.out_dir;
    if (!zip.has_filename()) zip = zip.parent_path();
    zip += ".gcvf";
    zip_stack(opt.out_dir, zip);
    sum.zip_file = zip;
  }
  sum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return sum;
}

}  // namespace trivox::io
