// `trivox slice MODEL -o DIR`: the print job: the PNG stack + ConfigFile.xml for GrabCAD Voxel Print
// (`--png`, the default) and/or the OpenVDB volume DIR/<model>.vdb (`--vdb`).
#include <tbb/global_control.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

#include "common.hpp"
#include "trivox/error.hpp"
#include "trivox/job/manifest.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/io/safe_path.hpp"
#include "trivox/io/sha256.hpp"
#include "trivox/job/slice_job.hpp"
#include "trivox/job/vdb_job.hpp"
#include "trivox/byte_size.hpp"
#include "trivox/version.hpp"

namespace trivox::cli {

namespace {

struct Options {
  std::string model, out, printer = "j750", dpi, palette, dither = "fs", progress = "auto", blend = "encoded";
  double layer = 0.0;
  int threads = 0;
  bool zip = false, force = false;
  int digits = 0;
  std::string background = "transparent";
  double max_voxels = 1e11;  // a double, so that 1e9 reads as the help writes it
  double max_layers = 1e5;
  std::string max_memory = "2G";
  bool dry_run = false;
  bool png = false, vdb = false;
  double vdb_voxel = 0.0;
  std::string vdb_units = "mm", vdb_color_space = "linear";
  int supersample = 1;
  bool resume = false;
  std::string shard;
  int shard_count = 0;
};

/// "2G", "1.5GiB", "512M", "800000000": a memory size in bytes (K, M, G, T are powers of 1024).
std::int64_t parse_bytes(const std::string& text, const std::string& option) {
  const auto bad = [&] {
    return Error(option + " " + text + ": not a memory size; expected a number of bytes, or with K, M, G or T " +
                 "(powers of 1024: 2G, 1.5GiB, 512M), from 64M to 1024T");
  };
  double v = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (ec != std::errc() || ptr == text.data() || !std::isfinite(v)) throw bad();
  std::string unit(ptr, end);
  if (unit.ends_with("iB")) unit.resize(unit.size() - 2);
  else if (unit.ends_with("B")) unit.resize(unit.size() - 1);
  double scale = 1;
  if (unit == "K" || unit == "k") scale = 1024.0;
  else if (unit == "M") scale = 1024.0 * 1024;
  else if (unit == "G") scale = 1024.0 * 1024 * 1024;
  else if (unit == "T") scale = 1024.0 * 1024 * 1024 * 1024;
  else if (!unit.empty()) throw bad();
  const double bytes = v * scale;
  if (!(bytes >= 64.0 * 1024 * 1024 && bytes <= 1024.0 * 1024 * 1024 * 1024 * 1024)) throw bad();
  return static_cast<std::int64_t>(bytes);
}

std::string duration(double s) {
  char buf[32];
  if (s < 60) std::snprintf(buf, sizeof buf, "%.1fs", s);
  else if (s < 3600) std::snprintf(buf, sizeof buf, "%dm%02ds", static_cast<int>(s) / 60, static_cast<int>(s) % 60);
  else std::snprintf(buf, sizeof buf, "%dh%02dm", static_cast<int>(s) / 3600, (static_cast<int>(s) / 60) % 60);
  return buf;
}

/// Progress on stderr: a bar redrawn in place on a terminal, a line every 5 s otherwise.
/// @param unit  what is counted ("layers"; "blocks" for the VDB's 8-layer blocks)
/// @param what  what per second ("voxels"; "samples")
job::SliceProgress make_progress(const std::string& mode, const char* unit = "layers", const char* what = "voxels") {
  if (mode == "never") return {};
  const bool bar = mode == "bar" || (mode == "auto" && isatty(STDERR_FILENO));
  // The rate and the ETA are measured from the first report on: the time before it holds the
  // model's setup (the locator) and a whole group of layers in flight, which would make the
  // first ETAs far too long (52 minutes for the 13-second teapot print).
  struct State {
    double last = -1e9;
    bool have_base = false;
    int base_done = 0;
    std::int64_t base_voxels = 0;
    double base_seconds = 0.0;
  };
  auto st = std::make_shared<State>();
  return [bar, st, unit, what](int done, int total, std::int64_t voxels, double seconds) {
    if (!st->have_base) {
      st->have_base = true;
      st->base_done = done, st->base_voxels = voxels, st->base_seconds = seconds;
    }
    const double span = seconds - st->base_seconds;
    const bool measured = done > st->base_done && span > 0.0;
    const double rate = measured ? static_cast<double>(voxels - st->base_voxels) / span : seconds > 0 ? voxels / seconds : 0.0;
    const std::string eta = done == total ? duration(0.0)
                            : measured   ? duration(span * (total - done) / (done - st->base_done))
                                         : std::string("--");
    if (bar) {
      const int width = 30, fill = total ? done * width / total : width;
      std::fprintf(stderr, "\r[%.*s%.*s] %d/%d %s, %.3g %s/s, ETA %s   ", fill, "##############################",
                   width - fill, "..............................", done, total, unit, rate, what, eta.c_str());
      if (done == total) std::fprintf(stderr, "\n");
    } else if (seconds - st->last >= 5.0 || done == total) {
      st->last = seconds;
      std::fprintf(stderr, "trivox slice: %d/%d %s, %.3g %s/s, elapsed %s, ETA %s\n", done, total, unit, rate, what,
                   duration(seconds).c_str(), eta.c_str());
    }
  };
}

nlohmann::ordered_json vdb_json(const job::VdbJobSummary& v) {
  nlohmann::ordered_json mats = nlohmann::ordered_json::array();
  for (std::size_t m = 0; m < v.materials.size(); ++m)
    mats.push_back({{"name", v.materials[m]}, {"volume_mm3", v.material_volume_mm3[m]}});
  return {{"file", v.file.string()},
          {"voxel_mm", v.plan.voxel_mm},
          {"voxel_automatic", v.plan.automatic},
          {"supersample", v.plan.supersample},
          {"grid", {{"origin", v.plan.origin}, {"count", v.plan.count}}},
          {"grids", v.grids},
          {"active_voxels", v.active_voxels},
          {"fractional_voxels", v.fractional_voxels},
          {"samples", v.samples},
          {"volume_mm3", v.volume_mm3},
          {"estimated_volume_mm3", v.plan.estimated_volume_mm3},
          {"estimated_memory_bytes", v.plan.estimated_memory_bytes},
          {"colour_source", v.colour_source},
          {"units", v.units},
          {"color_space", v.color_space},
          {"palette", v.palette},
          {"materials", mats},
          {"inversion_failures", v.inversion_failures},
          {"bytes", v.bytes},
          {"sha256", v.sha256},
          {"seconds", v.seconds}};
}

void print_vdb(const job::VdbJobSummary& v) {
  const auto& p = v.plan;
  std::string grids;
  for (const auto& g : v.grids) grids += (grids.empty() ? "" : ", ") + g;
  std::printf("vdb: %s: %zu grids (%s), %s\n", v.file.string().c_str(), v.grids.size(), grids.c_str(),
              file_size_text(static_cast<double>(v.bytes)).c_str());
  if (p.automatic)
    std::printf("voxel %s mm (automatic: volume %s mm^3 / voxel^3 = about %.3g active voxels, below %.3g and within the memory), supersample %d\n",
                fmt(p.voxel_mm, 6).c_str(), fmt(p.estimated_volume_mm3, 8).c_str(), p.estimated_active_voxels, 5e7,
                p.supersample);
  else
    std::printf("voxel %s mm (--vdb-voxel), supersample %d\n", fmt(p.voxel_mm, 6).c_str(), p.supersample);
  std::printf("box %d x %d x %d voxels from (%s, %s, %s) mm; time %s; memory estimated %s (--max-memory)\n", p.count[0],
              p.count[1], p.count[2], fmt(p.origin[0], 6).c_str(), fmt(p.origin[1], 6).c_str(), fmt(p.origin[2], 6).c_str(),
              duration(v.seconds).c_str(), memory_size_text(p.estimated_memory_bytes).c_str());
  std::printf("active voxels %lld (%lld fractional), volume %s mm^3 (quadrature %s mm^3)\n",
              static_cast<long long>(v.active_voxels), static_cast<long long>(v.fractional_voxels),
              fmt(v.volume_mm3, 8).c_str(), fmt(p.estimated_volume_mm3, 8).c_str());
  if (v.units != "mm") std::printf("world unit %s (the grids' transform: mm / 1000)\n", v.units.c_str());
  std::printf("colour from %s, %s; material volumes (fractions before dithering, palette %s):\n",
              v.colour_source == "r,g,b" ? "the model's r, g, b" : "the palette colours",
              v.color_space == "srgb" ? "sRGB-encoded" : "linear", v.palette.c_str());
  for (std::size_t m = 0; m < v.materials.size(); ++m)
    if (v.material_volume_mm3[m] > 0)
      std::printf("  %-16s %14.3f mm^3\n", v.materials[m].c_str(), v.material_volume_mm3[m]);
  std::printf("inversion failures: %lld\n", static_cast<long long>(v.inversion_failures));
}

/// `--dry-run`: what the job would write and cost, nothing written.
void print_dry_run(bool json, const std::string& model, const std::string& out, const job::SliceJobSummary* png,
                   const std::optional<job::VdbJobSummary>& vdb, std::int64_t max_memory) {
  nlohmann::ordered_json j = {{"model", model}, {"output", out}, {"dry_run", true}, {"max_memory_bytes", max_memory}};
  if (png) {
    const auto& e = png->estimate;
    j["png"] = {{"grid", png->grid.count},
                {"layers", e.layers},
                {"layer_range", png->layer_range},
                {"files", e.files},
                {"voxels", e.voxels},
                {"threads", e.threads},
                {"grouped", e.grouped},
                {"estimated_seconds", e.seconds},
                {"estimated_memory_bytes", e.memory_bytes},
                {"memory_held_bytes", e.base_bytes},
                {"estimated_output_bytes", e.output_bytes},
                {"timed_layers", e.timed_layers},
                {"seconds_per_layer", e.seconds_per_layer}};
  }
  if (vdb) {
    const auto& p = vdb->plan;
    j["vdb"] = {{"file", vdb->file.string()},
                {"voxel_mm", p.voxel_mm},
                {"automatic", p.automatic},
                {"supersample", p.supersample},
                {"box", p.count},
                {"estimated_active_voxels", p.estimated_active_voxels},
                {"estimated_seconds", vdb->estimated_seconds},
                {"estimated_memory_bytes", p.estimated_memory_bytes},
                {"estimated_output_bytes", p.estimated_active_voxels * p.grids_values * 4.0},
                {"tasks", vdb->tasks},
                {"timed_tasks", vdb->timed_tasks}};
  }
  if (json) {
    print_json(j);
    return;
  }
  std::printf("dry run of %s -> %s: nothing written\n", model.c_str(), out.c_str());
  if (png) {
    const auto& e = png->estimate;
    const auto& c = png->grid.count;
    std::printf("png: %d x %d pixels x %d layers; %d files (slices%s), %lld voxels\n", c[0], c[1], e.layers, e.files,
                png->shard.count == 1 ? ", ConfigFile.xml, manifest.json" : ", the shard's manifest",
                static_cast<long long>(e.voxels));
    std::printf("  time about %s on %d worker%s (%.3g s of CPU a layer, from %d layers); slices about %s\n",
                duration(e.seconds).c_str(), e.threads, e.threads == 1 ? "" : "s", e.seconds_per_layer, e.timed_layers,
                file_size_text(e.output_bytes).c_str());
    std::printf("  memory about %s (%s held before the job; --max-memory %s)%s\n", memory_size_text(e.memory_bytes).c_str(),
                memory_size_text(e.base_bytes).c_str(), memory_size_text(static_cast<double>(max_memory)).c_str(),
                e.grouped ? "; layers dithered 8 at a time" : "");
  }
  if (vdb) {
    const auto& p = vdb->plan;
    std::printf("vdb: %s: voxel %s mm%s, box %d x %d x %d, about %.3g active voxels\n", vdb->file.string().c_str(),
                fmt(p.voxel_mm, 6).c_str(), p.automatic ? " (automatic)" : "", p.count[0], p.count[1], p.count[2],
                p.estimated_active_voxels);
    std::printf("  time about %s (from %d of %d tasks); memory about %s (--max-memory %s); file about %s before compression\n",
                duration(vdb->estimated_seconds).c_str(), vdb->timed_tasks, vdb->tasks,
                memory_size_text(p.estimated_memory_bytes).c_str(), memory_size_text(static_cast<double>(max_memory)).c_str(),
                file_size_text(p.estimated_active_voxels * p.grids_values * 4.0).c_str());
  }
}

}  // namespace

void add_slice(CLI::App& app, Common& common) {
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("slice", "Slice a model into a GrabCAD Voxel Print PNG stack and/or an OpenVDB volume");
  sub->add_option("MODEL", opt->model, "Model file (.json, or G+Smo .xml)")->required();
  sub->add_option("-o,--output", opt->out, "Output folder (new or empty)")->required();
  sub->add_option("--printer", opt->printer, "Printer preset: j750, j850 (600 x 300 dpi, 27 um layers)");
  sub->add_option("--dpi", opt->dpi, "Custom resolution X,Y in dots per inch (overrides the preset)");
  sub->add_option("--layer", opt->layer, "Custom layer thickness in mm (overrides the preset)");
  sub->add_option("--palette", opt->palette, "Palette file (JSON); default: the Vero palette");
  sub->add_option("--dither", opt->dither, "fs (error diffusion, default), stochastic or none");
  sub->add_option("--blend", opt->blend,
                  "Shepard fillet cells: encoded (their control points, default) or shepard (the exact blend per voxel)");
  sub->add_flag("--zip", opt->zip, "Also pack the folder as <DIR>.gcvf");
  sub->add_option("--digits", opt->digits,
                  "Zero-pad slice numbers to N digits (default 0: slice_0.png, as Voxel Print tools name them)");
  sub->add_option("--background", opt->background,
                  "Void pixels: transparent (0 0 0 0, default) or black (0 0 0 255); declared in ConfigFile.xml");
  sub->add_flag("--force", opt->force,
                "Write into a non-empty folder (removing only what trivox wrote there); allow models beyond the tray");
  sub->add_option("--max-voxels", opt->max_voxels, "Refuse PNG jobs of more voxels (default 1e11)");
  sub->add_option("--max-layers", opt->max_layers, "Refuse PNG jobs of more layers, a file each (default 1e5)");
  sub->add_option("--max-memory", opt->max_memory,
                  "Memory a job may use (default 2G): the PNG job runs as many workers as fit, the VDB's automatic "
                  "voxel fits, a finer --vdb-voxel is refused");
  sub->add_flag("--dry-run", opt->dry_run,
                "Check everything, estimate the time, memory and output size from a few layers, write nothing");
  sub->add_option("--threads", opt->threads, "Worker threads (default: all cores)");
  sub->add_option("--progress", opt->progress, "auto (bar on a terminal, lines otherwise), bar, lines, never");
  sub->add_flag("--png", opt->png, "Write the PNG stack (the default without --vdb)");
  sub->add_flag("--vdb", opt->vdb, "Write the OpenVDB volume DIR/<model>.vdb (with --png: both)");
  sub->add_option("--vdb-voxel", opt->vdb_voxel, "VDB voxel edge in mm (default: about 5e7 active voxels)");
  sub->add_option("--vdb-units", opt->vdb_units,
                  "VDB world unit: mm (default; OpenVDB's tools) or m (Blender, Houdini: the transform / 1000)");
  sub->add_option("--vdb-color-space", opt->vdb_color_space,
                  "VDB color/Cd values: linear (default; what renderers expect) or srgb (the encoded colours)");
  sub->add_option("--supersample", opt->supersample, "VDB: N^3 samples per voxel for fractional density, 1..8 (default 1)");
  sub->add_flag("--resume", opt->resume, "Continue the job in DIR: keep the layers its manifest lists and that verify");
  sub->add_option("--shard", opt->shard, "Slice only part K of N of the layers (K from 0: 0/3, 1/3, 2/3); see trivox merge");
  sub->add_option("--shard-count", opt->shard_count, "Shards of a Kubernetes Indexed Job (the index: JOB_COMPLETION_INDEX)");
  sub->add_flag("--json", common.json, "Print the summary as one JSON object");
  sub->callback([opt, &common, sub] {
    const bool want_vdb = opt->vdb, want_png = opt->png || !opt->vdb;
    if (!want_vdb)
      for (const char* o : {"--vdb-voxel", "--vdb-units", "--vdb-color-space", "--supersample"})
        if (sub->count(o) > 0) throw Error(std::string(o) + ": applies to the VDB output; expected --vdb with it");
    if (!want_png)
      for (const char* o : {"--printer", "--dpi", "--layer", "--dither", "--zip", "--max-voxels", "--max-layers", "--digits", "--background"})
        if (sub->count(o) > 0)
          throw Error(std::string(o) + ": applies to the PNG stack; expected --png with it (--vdb alone writes only the VDB)");
    if (opt->progress != "auto" && opt->progress != "bar" && opt->progress != "lines" && opt->progress != "never")
      throw Error("--progress " + opt->progress + ": unknown mode; expected auto, bar, lines or never");
    if (!(opt->max_voxels >= 1 && opt->max_voxels <= 1e18 && std::floor(opt->max_voxels) == opt->max_voxels))
      throw Error("--max-voxels " + fmt(opt->max_voxels) + ": out of range; expected a whole number of voxels, 1 to 1e18");
    if (!(opt->max_layers >= 1 && opt->max_layers <= 1e9 && std::floor(opt->max_layers) == opt->max_layers))
      throw Error("--max-layers " + fmt(opt->max_layers) + ": out of range; expected a whole number of layers, 1 to 1e9");
    if (opt->dry_run && (opt->resume || opt->force))
      throw Error(std::string(opt->resume ? "--resume" : "--force") +
                  ": with --dry-run, which writes nothing and does not look at the folder; expected one or the other");
    const std::int64_t max_memory = parse_bytes(opt->max_memory, "--max-memory");
    if (opt->threads < 0 || opt->threads > 1024)
      throw Error("--threads " + std::to_string(opt->threads) + ": out of range; expected 1 to 1024 (0: all cores)");
    // The shard: --shard wins over a scheduler's environment (Slurm arrays, Kubernetes).
    job::Shard shard;
    if (!opt->shard.empty()) shard = job::parse_shard(opt->shard);
    else if (const auto env = job::shard_from_environment(sub->count("--shard-count") ? std::optional<int>(opt->shard_count) : std::nullopt))
      shard = *env;
    else if (sub->count("--shard-count"))
      throw Error("--shard-count " + std::to_string(opt->shard_count) +
                  ": without JOB_COMPLETION_INDEX in the environment; expected a Kubernetes Indexed Job, or --shard K/N");
    slice::SamplerOptions sampling;
    if (!slice::property_blend_from_name(opt->blend, sampling.blend))
      throw Error("--blend " + opt->blend + ": unknown; expected encoded or shepard");
    job::VdbJobOptions vj;
    if (!job::vdb_units_from_name(opt->vdb_units, vj.units))
      throw Error("--vdb-units " + opt->vdb_units + ": unknown unit; expected mm or m");
    if (!job::vdb_color_space_from_name(opt->vdb_color_space, vj.color_space))
      throw Error("--vdb-color-space " + opt->vdb_color_space + ": unknown colour space; expected linear or srgb");
    const auto model = io::load_model(opt->model);
    vj.sampler = sampling;
    std::optional<job::VdbPlan> plan;
    if (want_vdb) {
      vj.out_dir = opt->out;
      vj.model_file = opt->model;
      if (!opt->palette.empty()) vj.palette = opt->palette;
      if (sub->count("--vdb-voxel") > 0) vj.voxel_mm = opt->vdb_voxel;
      vj.supersample = opt->supersample;
      vj.max_memory_bytes = max_memory;
      vj.dry_run = opt->dry_run;
      vj.force = opt->force;
      vj.require_empty_folder = !want_png;
      plan = job::plan_vdb_job(model, vj);  // bad VDB options fail before the PNG stack is written
      // The later plans, and the PNG job, reuse its measures of the model.
      vj.model_box = plan->model_box;
      vj.model_volume_mm3 = plan->estimated_volume_mm3;
      if (shard.count > 1) {  // this shard's whole leaves, in a part of its own
        vj.layer_range = shard.range(plan->count[2]);
        vj.file_name = shard.part_name(plan->file.filename().string());
        plan = job::plan_vdb_job(model, vj);
      }
    }
    std::unique_ptr<tbb::global_control> limit;
    if (opt->threads > 0)
      limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    static_cast<std::size_t>(opt->threads));
    // The manifest's identity of the job (manifest.hpp): the model's bytes and the VDB's options.
    std::map<std::string, std::string> vdb_options{{"vdb", want_vdb ? "yes" : "no"}};
    // Part of the job's identity only when not the default, so earlier manifests still resume.
    if (sampling.blend != slice::PropertyBlend::encoded) vdb_options["blend"] = slice::property_blend_name(sampling.blend);
    if (plan) {
      vdb_options["vdb.voxel_mm"] = job::option_number(plan->voxel_mm);
      vdb_options["vdb.supersample"] = std::to_string(plan->supersample);
      // Like blend: only when not the default, so earlier manifests still resume.
      if (vj.units != job::VdbUnits::mm) vdb_options["vdb.units"] = job::vdb_units_name(vj.units);
      if (vj.color_space != job::VdbColorSpace::linear)
        vdb_options["vdb.color_space"] = job::vdb_color_space_name(vj.color_space);
    }
    const std::string model_sha = io::sha256_file(opt->model);
    vj.model_sha256 = model_sha;  // the VDB's metadata: hashed once
    // A resumed job keeps its VDB when the manifest lists it and it verifies.
    auto verified_vdb = [&]() -> std::optional<job::ManifestFile> {
      std::optional<job::Manifest> m;
      if (want_vdb && opt->resume) try {
          m = job::read_manifest(opt->out, shard.manifest_name());
        } catch (const Error&) {
        }
      if (m)
          for (const auto& f : m->files)
            if (f.role == "vdb" && f.file == plan->file.filename().string() &&
                io::sha256_regular_file(plan->file) == f.sha256)
              return f;
      return std::nullopt;
    };
    if (opt->dry_run) vj.require_empty_folder = false;  // the folder is not looked at
    if (!want_png && opt->dry_run) {
      print_dry_run(common.json, opt->model, opt->out, nullptr, job::run_vdb_job(model, vj), max_memory);
      return;
    }
    if (!want_png) {
      // A volume-only job: its manifest lists the VDB (a shard's: its part of whole leaves).
      job::Manifest id;
      id.trivox = version;
      id.model_file = opt->model;
      id.model_sha256 = model_sha;
      id.options = vdb_options;
      id.options["png"] = "no";
      id.options["vdb.palette"] =
          opt->palette.empty() ? std::string("(built in)") : io::sha256_file(opt->palette);
      id.grid = plan->count;
      id.shard = shard;
      id.layer_range = shard.range(plan->count[2]);
      const auto previous = job::prepare_job_folder(opt->out, id, opt->force, opt->resume);
      const auto kept = previous ? verified_vdb() : std::nullopt;
      std::optional<job::VdbJobSummary> v;
      if (!kept) {
        io::write_file_atomically(std::filesystem::path(opt->out) / shard.manifest_name(), job::manifest_json(id));
        vj.require_empty_folder = false;  // checked above, with the manifest
        v = job::run_vdb_job(model, vj, make_progress(opt->progress, "blocks", "samples"));
      }
      job::finish_manifest(opt->out, shard, {kept ? *kept : job::ManifestFile{"vdb", v->file.filename().string(), v->sha256}});
      if (common.json) {
        nlohmann::ordered_json j = {{"model", opt->model}, {"output", opt->out}};
        if (v) j["vdb"] = vdb_json(*v);
        else j["vdb_kept"] = kept->file;
        j["shard"] = {{"index", shard.index}, {"count", shard.count}};
        j["manifest"] = (std::filesystem::path(opt->out) / shard.manifest_name()).string();
        return print_json(j);
      }
      std::printf("sampled %s -> %s\n", opt->model.c_str(), opt->out.c_str());
      if (v) print_vdb(*v);
      else std::printf("resumed: %s kept (verified against the manifest)\n", kept->file.c_str());
      if (shard.count > 1)
        std::printf("shard %d/%d: VDB layers %d to %d; when every shard is done: trivox merge %s\n", shard.index,
                    shard.count, id.layer_range[0], id.layer_range[1] - 1, opt->out.c_str());
      return;
    }
    job::SliceJobOptions job;
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
    job.digits = opt->digits;
    job.background = opt->background;
    // Resuming continues the job as it was named and painted: unless given again, the slice
    // names and the void colour are the manifest's (an earlier trivox's padded names included).
    if (opt->resume) try {
        if (const auto m = job::read_manifest(opt->out, shard.manifest_name())) {
          if (sub->count("--digits") == 0 && m->options.count("png.digits")) job.digits = std::stoi(m->options.at("png.digits"));
          if (sub->count("--background") == 0 && m->options.count("png.background")) job.background = m->options.at("png.background");
        }
      } catch (const Error&) {
        // A damaged manifest: the job folder's check reports it (and --force moves it aside).
      }
    job.model_file = opt->model;
    job.model_sha256 = model_sha;
    job.extra_options = vdb_options;
    job.last_output = !want_vdb;  // the VDB follows and completes the manifest
    job.max_voxels = static_cast<std::int64_t>(opt->max_voxels);
    job.max_layers = static_cast<std::int64_t>(opt->max_layers);
    job.max_memory_bytes = max_memory;
    job.dry_run = opt->dry_run;
    job.resume = opt->resume;
    job.shard = shard;
    job.sampler = sampling;
    if (plan) job.model_box = plan->model_box;
    if (opt->dry_run) {
      const auto s = job::run_slice_job(model, job);
      std::optional<job::VdbJobSummary> v;
      if (want_vdb) v = job::run_vdb_job(model, vj);
      print_dry_run(common.json, opt->model, opt->out, &s, v, max_memory);
      return;
    }
    const std::optional<job::ManifestFile> vdb_done = verified_vdb();
    const auto s = job::run_slice_job(model, job, make_progress(opt->progress));
    std::optional<job::VdbJobSummary> v;
    if (want_vdb && vdb_done) {
      job::finish_manifest(opt->out, s.shard, {*vdb_done});
    } else if (want_vdb) {
      v = job::run_vdb_job(model, vj, make_progress(opt->progress, "blocks", "samples"));
      job::finish_manifest(opt->out, s.shard, {{"vdb", v->file.filename().string(), v->sha256}});
    }

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
                                {"background", job.background},
                                {"digits", job.digits},
                                {"max_materials", job.profile.channels},
                                {"grid", {{"origin", s.grid.origin}, {"pitch", s.grid.pitch}, {"count", s.grid.count}}},
                                {"layers", s.grid.count[2]},
                                {"voxels", s.voxels},
                                {"filled", s.filled},
                                {"seconds", s.seconds},
                                {"voxels_per_second", s.seconds > 0 ? s.voxels / s.seconds : 0.0},
                                {"inversion_failures", s.inversion_failures},
                                {"mapping", s.mapping},
                                {"materials", mats},
                                {"shard", {{"index", s.shard.index}, {"count", s.shard.count}}},
                                {"layer_range", s.layer_range},
                                {"layers_kept", s.layers_kept},
                                {"manifest", (std::filesystem::path(opt->out) / s.shard.manifest_name()).string()}};
    if (vdb_done) j["vdb_kept"] = vdb_done->file;
    if (!s.zip_file.empty()) j["zip"] = s.zip_file.string();
    if (job.zip) {
      j["mesh"] = s.mesh_file.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(s.mesh_file.string());
      j["mesh_warning"] = s.mesh_warning.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(s.mesh_warning);
    }
    // A warning, not a failure: the archive is complete without the mesh.
    if (!s.mesh_warning.empty()) std::fprintf(stderr, "trivox: warning: %s\n", s.mesh_warning.c_str());
    if (v) j["vdb"] = vdb_json(*v);
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
    if (s.shard.count > 1)
      std::printf("shard %d/%d: layers %d to %d; when every shard is done: trivox merge %s\n", s.shard.index,
                  s.shard.count, s.layer_range[0], s.layer_range[1] - 1, opt->out.c_str());
    if (s.layers_kept > 0) std::printf("resumed: %d layers kept (verified against the manifest)\n", s.layers_kept);
    if (vdb_done) std::printf("resumed: %s kept (verified against the manifest)\n", vdb_done->file.c_str());
    if (!s.mesh_file.empty()) std::printf("mesh: %s\n", s.mesh_file.string().c_str());
    if (!s.zip_file.empty()) std::printf("packed: %s\n", s.zip_file.string().c_str());
    if (v) print_vdb(*v);
  });
}

}  // namespace trivox::cli
