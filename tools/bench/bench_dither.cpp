// The print job's dither stage alone (issue 3): LayerGroupDitherer (8 layers per vector lane)
// against LayerDitherer::dither_paint one layer at a time, on synthetic rows shaped like the
// bench model's (a colour field over a disc that turns from layer to layer, void around it), on
// one thread. Prints ns per voxel and per live (non-void) voxel for each.
//
// Usage: trivox_bench_dither [NX [ROWS [REPEATS]]]   (defaults 1003 x 502, 5 repeats; best kept)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>
#include <time.h>

#include "trivox/slice/dither.hpp"
#include "trivox/slice/material.hpp"

using namespace trivox::slice;

namespace {
/// This thread's CPU time: figures a busy machine does not inflate with waits for a core.
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
}  // namespace

int main(int argc, char** argv) {
  const int nx = argc > 1 ? std::max(1, std::atoi(argv[1])) : 1003;
  const int ny = argc > 2 ? std::max(1, std::atoi(argv[2])) : 502;
  const int repeats = argc > 3 ? std::max(1, std::atoi(argv[3])) : 5;
  constexpr int L = LayerGroupDitherer::max_layers;
  const MaterialMapper mapper(default_palette(), {"r", "g", "b"});
  const int nmat = mapper.materials();
  const auto unx = static_cast<std::size_t>(nx), uny = static_cast<std::size_t>(ny);

  // Per layer: cells (a disc of radius 0.45 nx turned by 2 degrees a layer into a square-ish
  // section, so that the layers' voids differ at the edges) and smooth rgb.
  std::vector<std::vector<std::int32_t>> cell(L, std::vector<std::int32_t>(unx * uny));
  std::vector<std::vector<float>> props(L, std::vector<float>(unx * uny * 3));
  std::int64_t live = 0;
  for (int l = 0; l < L; ++l) {
    const double a = 0.035 * l, ca = std::cos(a), sa = std::sin(a);
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const double x = (i - 0.5 * nx) / nx, y = (j - 0.5 * ny) / ny * 0.5 * ny / nx * 2.0;
        const double u = ca * x - sa * y, v = sa * x + ca * y;
        const bool in = std::pow(std::abs(u), 4) + std::pow(std::abs(v), 4) < std::pow(0.42, 4);
        const std::size_t k = static_cast<std::size_t>(j) * unx + static_cast<std::size_t>(i);
        cell[static_cast<std::size_t>(l)][k] = in ? 0 : -1;
        live += in;
        float* p = props[static_cast<std::size_t>(l)].data() + 3 * k;
        p[0] = static_cast<float>(0.5 + 0.5 * std::sin(7.0 * u));
        p[1] = static_cast<float>(0.5 + 0.5 * std::cos(5.0 * v));
        p[2] = static_cast<float>(0.5 + 0.5 * std::sin(3.0 * (u + v)));
      }
  }
  std::array<std::uint32_t, 256> colours{};
  for (int m = 0; m < nmat; ++m) colours[static_cast<std::size_t>(m)] = 0xff000000u | static_cast<std::uint32_t>(m * 40);
  std::vector<std::vector<std::uint8_t>> rgba(L, std::vector<std::uint8_t>(unx * uny * 4));
  std::vector<std::vector<std::int64_t>> counts(L, std::vector<std::int64_t>(static_cast<std::size_t>(nmat), 0));
  const double voxels = static_cast<double>(L) * nx * ny;

  auto best_of = [&](auto&& run) {
    double best = 1e30;
    for (int r = 0; r < repeats; ++r) {
      const double t0 = cpu_seconds();
      run();
      best = std::min(best, cpu_seconds() - t0);
    }
    return best;
  };
  std::printf("trivox bench_dither: %d x %d, %d layers, %.1f%% live, best of %d, thread CPU time\n", nx, ny, L,
              100.0 * static_cast<double>(live) / voxels, repeats);
  std::printf("%-28s %12s %14s %16s\n", "ditherer", "seconds", "ns per voxel", "ns per live voxel");
  auto report = [&](const char* name, double s) {
    std::printf("%-28s %12.4f %14.2f %16.2f\n", name, s, 1e9 * s / voxels, 1e9 * s / static_cast<double>(live));
  };

  LayerDitherer one(DitherMode::fs, nx, nmat, 0.0423, 0.0847);
  report("one layer at a time", best_of([&] {
           for (int l = 0; l < L; ++l) {
             const auto ul = static_cast<std::size_t>(l);
             one.begin_layer(l);
             for (int j = 0; j < ny; ++j) {
               const std::size_t k = static_cast<std::size_t>(j) * unx;
               one.dither_paint(j, cell[ul].data() + k, props[ul].data() + 3 * k, mapper, colours, rgba[ul].data() + 4 * k,
                                counts[ul].data());
             }
           }
         }));
  if (!LayerGroupDitherer::serves(DitherMode::fs, mapper)) {
    std::printf("grouped kernel: not available on this CPU\n");
    return 0;
  }
  LayerGroupDitherer group(nx, mapper, 0.0423, 0.0847);
  report("8 layers in lanes", best_of([&] {
           group.begin(L);
           const std::int32_t* c[L];
           const float* p[L];
           std::uint8_t* o[L];
           std::int64_t* n[L];
           for (int j = 0; j < ny; ++j) {
             const std::size_t k = static_cast<std::size_t>(j) * unx;
             for (std::size_t l = 0; l < L; ++l) {
               c[l] = cell[l].data() + k;
               p[l] = props[l].data() + 3 * k;
               o[l] = rgba[l].data() + 4 * k;
               n[l] = counts[l].data();
             }
             group.dither_paint(j, c, p, colours, o, n);
           }
         }));
  return 0;
}
