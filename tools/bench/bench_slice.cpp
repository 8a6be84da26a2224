// The print job's speed and memory (issue 3's benchmark), on the demo model (four tricubic cells
// with an rgb field) or a model given on the command line.
//
// 1. The whole job at J750 settings with 2 threads, against the floor: encoding and writing the
//    same PNGs from memory with the same settings and threads (the slices are decoded back first,
//    untimed). Prints seconds, voxels per second, the ratio job / floor and both per layer.
//    With a model at its own height (LAYERS_FOR_STEP_1 = 0) this is a full print job, e.g. the
//    teapot's (issue 7's benchmark: build models/teapot.json first, pass the built model).
// 2. One 1516 x 2524 pixel slice (the papers' example size): the model scaled to 64.2 x 213.7 mm
//    in xy and to one layer in z, sliced on one thread.
// 3. Peak memory of a full-tray-width J750 layer (11,575 x 4,606 px): the model scaled to the
//    tray (490 x 390 mm) and to `tray_layers` layers; ru_maxrss after the job (run first).
//
// Usage: trivox_bench_slice [MODEL [LAYERS_FOR_STEP_1 [TRAY_LAYERS [THREADS [REPEATS]]]]]
//   LAYERS_FOR_STEP_1: scale the model's height to this many J750 layers (0: keep its height).
//   TRAY_LAYERS: 0 skips step 3. THREADS (default 2): for step 1 and its floor.
//   REPEATS (default 5): step 1's job and floor each run this many times, alternating (job,
//   floor, job, floor, ...), so that a shared machine's slow spells fall on both alike; the
//   ratio is that of the medians, and the minima and their ratio are printed too.
// With TRIVOX_BENCH_JOB_ONLY=1 only the job of step 1 runs (for callgrind: repeatable
// instruction counts of the job alone).
#include <sys/resource.h>
#include <unistd.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "trivox/io/model_file.hpp"
#include "trivox/job/slice_job.hpp"
#include "trivox/io/png_image.hpp"
#include "trivox/io/stack_config.hpp"
#include "trivox/slice/sampler.hpp"

using namespace trivox;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

/// The model with xyz mapped affinely so its box becomes [0, size] (a size of 0 keeps the axis).
vmodel::VModel scaled(const vmodel::VModel& m, std::array<double, 3> size) {
  const auto box = slice::model_bounds(m);
  vmodel::VModel out = m;
  for (auto& c : out.cells)
    for (int r = 0; r < c.volume.size(); ++r) {
      auto p = c.volume.point(r);
      for (std::size_t d = 0; d < 3; ++d) {
        const double ext = box[1][d] - box[0][d];
        if (size[d] > 0 && ext > 0) p[d] = (p[d] - box[0][d]) * size[d] / ext;
      }
    }
  return out;
}

job::SliceJobSummary run(const vmodel::VModel& m, const fs::path& dir, int threads) {
  fs::remove_all(dir);
  job::SliceJobOptions opt;
  opt.profile = slice::printer_preset("j750");
  opt.out_dir = dir;
  opt.force = true;
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
  return job::run_slice_job(m, opt);
}

/// A job's pipeline thread-seconds outside its stages (writing and idle).
double outside_stages(const job::SliceJobSummary& job, int threads) {
  double staged = 0.0;
  for (double x : job.stage_seconds) staged += x;
  return threads * job.pipeline_seconds - staged;
}

}  // namespace

int main(int argc, char** argv) {
  const fs::path model_path = argc > 1 ? argv[1] : "models/twisted_column.json";
  const int layers = argc > 2 ? std::atoi(argv[2]) : 0;
  const int tray_layers = argc > 3 ? std::atoi(argv[3]) : 2;
  const int threads = argc > 4 ? std::max(1, std::atoi(argv[4])) : 2;
  const int repeats = argc > 5 ? std::max(1, std::atoi(argv[5])) : 5;
  const char* job_only_env = std::getenv("TRIVOX_BENCH_JOB_ONLY");
  const bool job_only = job_only_env && std::string(job_only_env) == "1";
  const fs::path tmp = fs::temp_directory_path() / ("trivox-bench-slice-" + std::to_string(getpid()));
  vmodel::VModel model = io::load_model(model_path);
  if (layers > 0) model = scaled(model, {0, 0, layers * 0.027});

  // 3 (run first, so the peak is this job's). Peak memory for full-tray-width layers.
  if (tray_layers > 0 && !job_only) {
    const auto tray = scaled(model, {490.0 - 1e-6, 390.0 - 1e-6, tray_layers * 0.027});
    const auto s = run(tray, tmp / "tray", 2);
    rusage ru{};
    getrusage(RUSAGE_SELF, &ru);
    std::printf("%-44s %12.3f %14.4g\n",
                ("tray " + std::to_string(s.grid.count[0]) + " x " + std::to_string(s.grid.count[1]) + " x " +
                 std::to_string(s.grid.count[2]))
                    .c_str(),
                s.seconds, s.voxels / s.seconds);
    std::printf("peak memory of the tray job (ru_maxrss): %.1f MB\n", ru.ru_maxrss / 1024.0);
  }
  // 1. The job against the floor, alternating. A pixel encoded first loads the PNG module
  // (src/io/png_codec.hpp, about 0.3 s), which the job's time should not count.
  {
    const std::uint8_t pixel[4] = {0, 0, 0, 0};
    (void)io::encode_png_rgba(pixel, 1, 1, 0, 0);
  }
  const auto job0 = run(model, tmp / "job", threads);
  if (job_only) {
    std::printf("job: %d x %d x %d, %.3f s, pipeline %.3f s, stages (ns per voxel):", job0.grid.count[0],
                job0.grid.count[1], job0.grid.count[2], job0.seconds, job0.pipeline_seconds);
    for (std::size_t i = 0; i < job0.stage_seconds.size(); ++i)
      std::printf(" %s %.1f", job::slice_stage_names[i], 1e9 * job0.stage_seconds[i] / static_cast<double>(job0.voxels));
    std::printf(", outside the stages %.3f thread-s\n", outside_stages(job0, threads));
    fs::remove_all(tmp);
    return 0;
  }
  std::vector<std::string> names;
  std::vector<io::RgbaImage> images;
  const auto cfg = io::read_stack_config(tmp / "job");
  for (int i = 0; i < cfg.slices; ++i) {
    names.push_back(cfg.slice_name(i));
    images.push_back(io::decode_png_rgba(io::read_file(tmp / "job" / names.back()), names.back()));
  }
  const auto floor_once = [&] {
    fs::remove_all(tmp / "floor");
    fs::create_directories(tmp / "floor");
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
    const auto t0 = Clock::now();
    tbb::parallel_for(std::size_t{0}, images.size(), [&](std::size_t i) {
      const auto& im = images[i];
      io::write_file_atomically(tmp / "floor" / names[i],
                                io::encode_png_rgba(im.pixels.data(), im.width, im.height, cfg.dpi_x, cfg.dpi_y),
                                io::Durability::deferred);
    });
    io::sync_folder_contents(tmp / "floor");  // as the job does before its ConfigFile.xml
    return since(t0);
  };
  // The first job above warmed the caches and wrote the reference slices; these are timed.
  std::vector<job::SliceJobSummary> jobs;
  std::vector<double> floors;
  for (int r = 0; r < repeats; ++r) {
    jobs.push_back(run(model, tmp / "job", threads));
    floors.push_back(floor_once());
  }
  std::vector<std::size_t> by_time(jobs.size());
  for (std::size_t i = 0; i < by_time.size(); ++i) by_time[i] = i;
  std::sort(by_time.begin(), by_time.end(), [&](std::size_t a, std::size_t b) { return jobs[a].seconds < jobs[b].seconds; });
  const auto& job = jobs[by_time[by_time.size() / 2]];  // the median job (the upper one of an even count)
  std::vector<double> sorted_floors = floors;
  std::sort(sorted_floors.begin(), sorted_floors.end());
  const double floor_s = sorted_floors[sorted_floors.size() / 2];
  const double job_min = jobs[by_time.front()].seconds, floor_min = sorted_floors.front();
  std::printf("trivox bench_slice: %s, J750 600 x 300 dpi, 27 um layers, %d threads, medians of %d alternating runs\n",
              model_path.c_str(), threads, repeats);
  std::printf("%-44s %12s %14s %8s\n", "step", "seconds", "voxels/s", "ratio");
  std::printf("%-44s %12.3f %14.4g %8s\n",
              ("job: " + std::to_string(job.grid.count[0]) + " x " + std::to_string(job.grid.count[1]) + " x " +
               std::to_string(job.grid.count[2]))
                  .c_str(),
              job.seconds, job.voxels / job.seconds, "");
  std::printf("%-44s %12.3f %14.4g %8.2f\n", "floor: encode + write the same PNGs", floor_s, job.voxels / floor_s,
              job.seconds / floor_s);
  std::printf("minima: job %.3f s, floor %.3f s, ratio %.2f; all runs (job/floor):", job_min, floor_min,
              job_min / floor_min);
  for (std::size_t r = 0; r < jobs.size(); ++r) std::printf(" %.3f/%.3f", jobs[r].seconds, floors[r]);
  std::printf("\n");
  std::printf("per layer: job %.2f ms, floor %.2f ms\n", 1e3 * job.seconds / job.grid.count[2], 1e3 * floor_s / job.grid.count[2]);
  std::printf("inversion failures: %lld\n", static_cast<long long>(job.inversion_failures));
  std::printf("median job's stages, thread-seconds (ns per voxel):");
  for (std::size_t i = 0; i < job.stage_seconds.size(); ++i)
    std::printf(" %s %.3f (%.1f)", job::slice_stage_names[i], job.stage_seconds[i],
                1e9 * job.stage_seconds[i] / static_cast<double>(job.voxels));
  std::printf("\n");
  std::printf("job pipeline (layers sampled to files written): %.3f s wall; thread-seconds outside the stages (writing "
              "and idle): %.3f\n",
              job.pipeline_seconds, outside_stages(job, threads));

  // 2. One 1516 x 2524 slice on one thread.
  {
    // A hundredth of a voxel less than 1516 x 2524 pitches: exactly that many voxels (2524 pitches
    // in floating point cover 2524.0000001 of them, and the grid rounds up).
    const auto one = scaled(model, {1515.99 * 25.4 / 600, 2523.99 * 25.4 / 300, 0.027});
    const auto s = run(one, tmp / "one", 1);
    std::printf("%-44s %12.3f %14.4g\n",
                ("one slice " + std::to_string(s.grid.count[0]) + " x " + std::to_string(s.grid.count[1]) +
                 ", 1 thread")
                    .c_str(),
                s.seconds, s.voxels / s.seconds);
  }
  fs::remove_all(tmp);
  return 0;
}
