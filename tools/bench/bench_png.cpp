// PNG slice encoding speed (io::encode_png_rgba), one thread: a full-tray J750 slice
// (11575 x 4606 RGBA, 600 x 300 dpi) in three contents: all void; mostly void with a solid
// ellipse of one material (25% of the area); the same ellipse dithered over three materials
// (a deterministic hash per pixel, the worst case for zlib). Prints MB/s of raw RGBA in,
// megapixels/s, bytes out, and checks each encoding decodes back to the same pixels.
//
// Not part of ctest. Build by hand against the library, e.g.
//   g++ -std=c++20 -O2 -Iinclude tools/bench/bench_png.cpp build/libtrivox_core.a
//       -lOpenImageIO -lOpenImageIO_Util -ltbb -lzip -lpugixml -o bench_png
// or with a CMake target like trivox_bench_eval's. Run: bench_png [width height [repeats]]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "trivox/io/png_image.hpp"

namespace {

using Clock = std::chrono::steady_clock;

std::vector<std::uint8_t> make_slice(int w, int h, int content) {
  std::vector<std::uint8_t> px(static_cast<std::size_t>(w) * h * 4, 0);
  const std::uint8_t pal[3][4] = {{0, 137, 166, 255}, {198, 0, 88, 255}, {240, 197, 0, 255}};
  if (content == 0) return px;
  const double cx = w / 2.0, cy = h / 2.0, rx = w * 0.282, ry = h * 0.282;  // pi*rx*ry = 0.25*w*h
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double dx = (x + 0.5 - cx) / rx, dy = (y + 0.5 - cy) / ry;
      if (dx * dx + dy * dy > 1) continue;
      std::uint32_t k = 0;
      if (content == 2) {
        std::uint32_t s = static_cast<std::uint32_t>(x) * 73856093u ^ static_cast<std::uint32_t>(y) * 19349663u;
        s ^= s >> 13, s *= 0x5bd1e995u, s ^= s >> 15;
        k = s % 3;
      }
      std::memcpy(&px[(static_cast<std::size_t>(y) * w + x) * 4], pal[k], 4);
    }
  return px;
}

}  // namespace

int main(int argc, char** argv) {
  const int w = argc > 2 ? std::atoi(argv[1]) : 11575, h = argc > 2 ? std::atoi(argv[2]) : 4606;
  const int repeats = argc > 3 ? std::atoi(argv[3]) : 3;
  const char* names[] = {"all void", "void + solid ellipse (25%)", "void + dithered ellipse (25%)"};
  std::printf("encode_png_rgba, %d x %d RGBA (%.1f MB raw), zlib level 1, no row filter, 1 thread, best of %d\n", w, h,
              w * 4.0 * h / 1e6, repeats);
  std::printf("%-32s %10s %10s %10s %12s\n", "content", "seconds", "MB/s", "Mpx/s", "PNG bytes");
  for (int content = 0; content < 3; ++content) {
    const auto px = make_slice(w, h, content);
    double best = 1e30;
    std::string png;
    for (int r = 0; r < repeats; ++r) {
      const auto t0 = Clock::now();
      png = trivox::io::encode_png_rgba(px.data(), w, h, 600, 300);
      best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count());
    }
    const auto back = trivox::io::decode_png_rgba(png, "bench");
    const bool same = back.pixels == px;
    std::printf("%-32s %10.3f %10.1f %10.1f %12zu%s\n", names[content], best, w * 4.0 * h / 1e6 / best,
                w * 1.0 * h / 1e6 / best, png.size(), same ? "" : "  DECODE MISMATCH");
    if (!same) return 1;
  }
  return 0;
}
