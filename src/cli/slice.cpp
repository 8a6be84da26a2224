// `trivox slice MODEL -o DIR`: the print job (PNG stack + ConfigFile.xml for GrabCAD Voxel Print).
#include <tbb/global_control.h>
#include <unistd.h>

#include <cstdio>
#include <memory>

#include "common.hpp"
#include "trivox/error.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/io/slice_job.hpp"

namespace trivox::cli {

namespace {

struct Options {
  std::string model, out, printer = "j750", dpi, palette, dither = "fs", progress = "auto";
  double layer = 0.0;
  int threads = 0;
  bool zip = false, force = false;
  std::int64_t max_voxels = 100'000'000'000;
};

std::string duration(double s) {
  char buf[32];
  if (s < 60) std::snprintf(buf, sizeof buf, "%.1fs", s);
  else if (s < 3600) std::snprintf(buf, sizeof buf, "%dm%02ds", static_cast<int>(s) / 60, static_cast<int>(s) % 60);
  else std::snprintf(buf, sizeof buf, "%dh%02dm", static_cast<int>(s) / 3600, (static_cast<int>(s) / 60) % 60);
  return buf;
}

/// Progress on stderr: a bar redrawn in place on a terminal, a line every 5 s otherwise.
io::SliceProgress make_progress(const std::string& mode) {
  if (mode == "never") return {};
  const bool bar = mode == "bar" || (mode == "auto" && isatty(STDERR_FILENO));
  auto last = std::make_shared<double>(-1e9);
  return [bar, last](int done, int total, std::int64_t voxels, double seconds) {
    const double rate = seconds > 0 ? voxels / seconds : 0.0;
    const double eta = done > 0 ? seconds * (total - done) / done : 0.0;
    if (bar) {
      const int width = 30, fill = total ? done * width / total : width;
      std::fprintf(stderr, "\r[%.*s%.*s] %d/%d layers, %.3g voxels/s, ETA %s   ", fill,
                   "##############################", width - fill, "..............................", done, total,
                   rate, duration(eta).c_str());
      if (done == total) std::fprintf(stderr, "\n");
    } else if (seconds - *last >= 5.0 || done == total) {
      *last = seconds;
      std::fprintf(stderr, "trivox slice: %d/%d layers, %.3g voxels/s, elapsed %s, ETA %s\n", done, total, rate,
                   duration(seconds).c_str(), duration(eta).c_str());
    }
  };
}

}  // namespace

void add_slice(CLI::App& app, Common& common) {
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("slice", "Slice a model into a GrabCAD Voxel Print PNG stack");
  sub->add_option("MODEL", opt->model, "Model file (.json, or G+Smo .xml)")->required();
  sub->add_option("-o,--output", opt->out, "Output folder (new or empty)")->required();
  sub->add_option("--printer", opt->printer, "Printer preset: j750, j850 (600 x 300 dpi, 27 um layers)");
  sub->add_option("--dpi", opt->dpi, "Custom resolution X,Y in dots per inch (overrides the preset)");
  sub->add_option("--layer", opt->layer, "Custom layer thickness in mm (overrides the preset)");
  sub->add_option("--palette", opt->palette, "Palette file (JSON); default: the Vero palette");
  sub->add_option("--dither", opt->dither, "fs (error diffusion, default), stochastic or none");
  sub->add_flag("--zip", opt->zip, "Also pack the folder as <DIR>.gcvf");
  sub->add_flag("--force", opt->force, "Write into a non-empty folder; allow jobs beyond the tray or --max-voxels");
  sub->add_option("--max-voxels", opt->max_voxels, "Refuse larger grids unless --force (default 1e11)");
  sub->add_option("--threads", opt->threads, "Worker threads (default: all cores)");
  sub->add_option("--progress", opt->progress, "auto (bar on a terminal, lines otherwise), bar, lines, never");
  sub->add_flag("--json", common.json, "Print the summary as one JSON object");
  sub->callback([opt, &common] {
    if (opt->progress != "auto" && opt->progress != "bar" && opt->progress != "lines" && opt->progress != "never")
      throw Error("--progress " + opt->progress + ": unknown mode; expected auto, bar, lines or never");
    if (opt->threads < 0 || opt->threads > 1024)
      throw Error("--threads " + std::to_string(opt->threads) + ": out of range; expected 1 to 1024 (0: all cores)");
    const auto model = io::load_model(opt->model);
    io::SliceJobOptions job;
    job.profile = slice::printer_preset(opt->printer);
    if (!opt->dpi.empty()) {
      const auto d = parse_numbers(opt->dpi, 2, "--dpi");
      job.profile.dpi_x = d[0];
      job.profile.dpi_y = d[1];
      job.profile.name = "custom";
    }
    if (opt->layer != 0.0) {
      job.profile.layer_mm = opt->layer;
      job.profile.name = "custom";
    }
    job.out_dir = opt->out;
    job.model_name = opt->model;
    if (!opt->palette.empty()) job.palette = opt->palette;
    job.dither = opt->dither;
    job.force = opt->force;
    job.zip = opt->zip;
    job.max_voxels = opt->max_voxels;
    std::unique_ptr<tbb::global_control> limit;
    if (opt->threads > 0)
      limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    static_cast<std::size_t>(opt->threads));
    const auto s = io::run_slice_job(model, job, make_progress(opt->progress));

    nlohmann::ordered_json mats = nlohmann::ordered_json::array();
    for (std::size_t m = 0; m < s.materials.size(); ++m)
      mats.push_back({{"name", s.materials[m]},
                      {"rgba", s.colours[m]},
                      {"voxels", s.material_voxels[m]},
                      {"volume_mm3", s.material_voxels[m] * s.voxel_volume_mm3}});
    nlohmann::ordered_json j = {{"model", opt->model},
                                {"output", opt->out},
                                {"printer", job.profile.name},
                                {"dpi", {job.profile.dpi_x, job.profile.dpi_y}},
                                {"layer_mm", job.profile.layer_mm},
                                {"grid", {{"origin", s.grid.origin}, {"pitch", s.grid.pitch}, {"count", s.grid.count}}},
                                {"layers", s.grid.count[2]},
                                {"voxels", s.voxels},
                                {"filled", s.filled},
                                {"seconds", s.seconds},
                                {"voxels_per_second", s.seconds > 0 ? s.voxels / s.seconds : 0.0},
                                {"inversion_failures", s.inversion_failures},
                                {"mapping", s.mapping},
                                {"materials", mats}};
    if (!s.zip_file.empty()) j["zip"] = s.zip_file.string();
    if (common.json) return print_json(j);
    std::printf("sliced %s -> %s: %d x %d pixels x %d layers (%s, %g x %g dpi, %g mm layers)\n", opt->model.c_str(),
                opt->out.c_str(), s.grid.count[0], s.grid.count[1], s.grid.count[2], job.profile.name.c_str(),
                job.profile.dpi_x, job.profile.dpi_y, job.profile.layer_mm);
    std::printf("time %s, %lld voxels (%.3g voxels/s), %lld filled\n", duration(s.seconds).c_str(),
                static_cast<long long>(s.voxels), s.seconds > 0 ? s.voxels / s.seconds : 0.0,
                static_cast<long long>(s.filled));
    std::printf("materials (%s):\n", s.mapping.c_str());
    for (std::size_t m = 0; m < s.materials.size(); ++m)
      if (s.material_voxels[m] > 0)
        std::printf("  %-16s %14lld voxels %14.3f mm^3\n", s.materials[m].c_str(),
                    static_cast<long long>(s.material_voxels[m]), s.material_voxels[m] * s.voxel_volume_mm3);
    std::printf("inversion failures: %lld\n", static_cast<long long>(s.inversion_failures));
    if (!s.zip_file.empty()) std::printf("packed: %s\n", s.zip_file.string().c_str());
  });
}

}  // namespace trivox::cli
