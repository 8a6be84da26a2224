// What a job spends before its first voxel, step by step, on a model (default: the twisted
// column; the filleted teapot is `output/teapot.json` after `tools/demo.sh` or `trivox build`):
// reading and checking the model file, its bounding box (slice::model_bounds, which the grid
// covers), the cells' quadrature volumes (the VDB job's automatic voxel size) and the sampler
// (Locator and LayerSampler) for the J750 grid. Wall-clock seconds with all threads, best of
// REPEATS runs (default 1).
//
// Usage: trivox_bench_setup [MODEL [REPEATS]]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "trivox/geom/quadrature.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/job/slice_job.hpp"
#include "trivox/slice/grid.hpp"
#include "trivox/slice/locator.hpp"
#include "trivox/slice/sampler.hpp"

using namespace trivox;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

/// The best wall-clock time of `repeats` runs of f.
double best_of(int repeats, const std::function<void()>& f) {
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = Clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count());
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  const fs::path model_path = argc > 1 ? argv[1] : fs::path(TRIVOX_SOURCE_DIR) / "models/twisted_column.json";
  const int repeats = argc > 2 ? std::max(1, std::atoi(argv[2])) : 1;
  try {
    vmodel::VModel model;
    const double t_load = best_of(repeats, [&] { model = io::load_model(model_path); });
    std::array<slice::Vec3, 2> box{};
    const double t_box = best_of(repeats, [&] { box = slice::model_bounds(model); });
    std::vector<double> volumes(model.cells.size());
    const double t_volume = best_of(repeats, [&] {
      for (std::size_t c = 0; c < model.cells.size(); ++c) volumes[c] = geom::volume(model.cells[c].volume);
    });
    const slice::VoxelGrid grid = job::slice_grid(model, slice::printer_preset("j750"));
    const double t_sampler = best_of(repeats, [&] { const slice::LayerSampler sampler(model, grid); });
    double total_volume = 0.0;
    for (double v : volumes) total_volume += v;
    std::printf("trivox bench_setup: %s, %zu cells, J750 grid %d x %d x %d, best of %d\n", model_path.string().c_str(),
                model.cells.size(), grid.count[0], grid.count[1], grid.count[2], repeats);
    std::printf("%-52s %10s\n", "step", "seconds");
    std::printf("%-52s %10.3f\n", "read and check the model file", t_load);
    std::printf("%-52s %10.3f\n", "bounding box (model_bounds)", t_box);
    std::printf("%-52s %10.3f\n", "cell volumes (quadrature)", t_volume);
    std::printf("%-52s %10.3f\n", "sampler for the J750 grid (Locator, LayerSampler)", t_sampler);
    std::printf("box (%.6g, %.6g, %.6g) - (%.6g, %.6g, %.6g) mm, volume %.6f mm^3\n", box[0][0], box[0][1], box[0][2],
                box[1][0], box[1][1], box[1][2], total_volume);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "trivox_bench_setup: %s\n", e.what());
    return 2;
  }
  return 0;
}
