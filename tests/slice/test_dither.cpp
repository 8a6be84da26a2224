// Dithering: material shares over regions of constant fractions (the 2 percent
// contract), independence from banding, void handling, and the error-diffusion weights.
// Set TRIVOX_PRINT_SHARES=1 to print the measured shares.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "trivox/error.hpp"
#include "trivox/slice/dither.hpp"
#include "trivox/slice/material.hpp"

namespace {

using namespace trivox::slice;

/// One layer's input: cell ids (-1 void) and fractions, row-major.
struct Layer {
  int nx = 0, ny = 0, m = 0;
  std::vector<std::int32_t> cell;
  std::vector<float> fractions;

  Layer(int nx_, int ny_, int m_)
      : nx(nx_), ny(ny_), m(m_), cell(static_cast<std::size_t>(nx_) * ny_, 0),
        fractions(static_cast<std::size_t>(nx_) * ny_ * m_, 0.0f) {}
  std::size_t at(int x, int y) const { return static_cast<std::size_t>(y) * nx + x; }
  void set(int x, int y, const std::vector<float>& f) {
    for (int k = 0; k < m; ++k) fractions[at(x, y) * m + k] = f[k];
  }
  void fill(const std::vector<float>& f) {
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) set(x, y, f);
  }
};

/// Dithers `layer` in bands whose heights cycle through `bands`.
std::vector<std::uint8_t> run(const Layer& layer, DitherMode mode, const std::vector<int>& bands = {64},
                              int index = 0, std::uint64_t seed = 0, double px = 0.0423, double py = 0.0847) {
  LayerDitherer d(mode, layer.nx, layer.m, px, py, seed);
  d.begin_layer(index);
  std::vector<std::uint8_t> out(layer.cell.size(), 7);
  std::size_t b = 0;
  for (int r0 = 0; r0 < layer.ny;) {
    const int rows = std::min(bands[b++ % bands.size()], layer.ny - r0);
    const std::size_t at = layer.at(0, r0);
    d.dither(r0, rows, layer.cell.data() + at, layer.fractions.data() + at * layer.m, out.data() + at);
    r0 += rows;
  }
  return out;
}

std::vector<double> shares(const std::vector<std::uint8_t>& out, int m) {
  std::vector<double> count(static_cast<std::size_t>(m), 0.0);
  std::size_t filled = 0;
  for (std::uint8_t v : out)
    if (v != void_material) {
      REQUIRE(v < m);
      count[v] += 1, ++filled;
    }
  for (double& c : count) c /= static_cast<double>(filled);
  return count;
}

bool print_shares() { return std::getenv("TRIVOX_PRINT_SHARES") != nullptr; }

}  // namespace

TEST_CASE("dither modes parse, and refuse anything else", "[dither]") {
  CHECK(parse_dither_mode("fs") == DitherMode::fs);
  CHECK(parse_dither_mode("stochastic") == DitherMode::stochastic);
  CHECK(parse_dither_mode("none") == DitherMode::none);
  for (DitherMode m : {DitherMode::fs, DitherMode::stochastic, DitherMode::none})
    CHECK(parse_dither_mode(dither_mode_name(m)) == m);
  for (const char* bad : {"", "FS", "floyd", "fs "}) {
    try {
      parse_dither_mode(bad);
      FAIL("accepted " << bad);
    } catch (const trivox::Error& e) {
      CHECK(e.kind() == trivox::ErrorKind::bad_input);
      CHECK(std::string(e.what()) == "--dither " + std::string(bad) + ": expected fs, stochastic or none");
    }
  }
}

TEST_CASE("diffusion weights: Floyd-Steinberg on square voxels, scaled by inverse distance otherwise", "[dither]") {
  const DiffusionWeights sq = diffusion_weights(0.05, 0.05);
  CHECK(sq.forward == Approx(7.0 / 16));
  CHECK(sq.down_back == Approx(3.0 / 16));
  CHECK(sq.down == Approx(5.0 / 16));
  CHECK(sq.down_forward == Approx(1.0 / 16));

  // Voxel 1 x 2: forward at distance 1 (square: 1), down at 2 (1), diagonals at sqrt(5) (sqrt(2)).
  const double d = std::sqrt(2.0 / 5.0), sum = 7 + 3 * d + 5.0 / 2 + d;
  const DiffusionWeights w = diffusion_weights(0.1, 0.2);
  CHECK(w.forward == Approx(7 / sum));
  CHECK(w.down_back == Approx(3 * d / sum));
  CHECK(w.down == Approx(2.5 / sum));
  CHECK(w.down_forward == Approx(d / sum));
  CHECK(w.forward + w.down_back + w.down + w.down_forward == Approx(1.0));
  // J750: 600 x 300 dpi, the documented figures.
  const DiffusionWeights j = diffusion_weights(25.4 / 600, 25.4 / 300);
  CHECK(j.forward == Approx(0.582).margin(5e-4));
  CHECK(j.down_back == Approx(0.158).margin(5e-4));
  CHECK(j.down == Approx(0.208).margin(5e-4));
  CHECK(j.down_forward == Approx(0.053).margin(5e-4));

  for (double bad : {0.0, -1.0, std::nan(""), HUGE_VAL}) CHECK_THROWS_AS(diffusion_weights(bad, 1.0), trivox::Error);
  CHECK_THROWS_AS(LayerDitherer(DitherMode::fs, 0, 2, 1, 1), trivox::Error);
  CHECK_THROWS_AS(LayerDitherer(DitherMode::fs, 4, 0, 1, 1), trivox::Error);
  CHECK_THROWS_AS(LayerDitherer(DitherMode::fs, 4, 255, 1, 1), trivox::Error);
  CHECK_THROWS_AS(LayerDitherer(DitherMode::fs, 4, 2, 1, 0), trivox::Error);
}

TEST_CASE("over a region of constant fractions each material's share is within 2 percent", "[dither]") {
  const std::vector<std::vector<float>> cases = {
      {0.5f, 0.5f},
      {0.3f, 0.7f},
      {0.1f, 0.9f},
      {0.02f, 0.98f},
      {0.2f, 0.3f, 0.5f},
      {0.01f, 0.33f, 0.66f},
      {0.1f, 0.2f, 0.3f, 0.4f},
      {0.25f, 0.25f, 0.25f, 0.25f},
      {0.15f, 0.0f, 0.35f, 0.05f, 0.45f, 0.0f},       // the default palette's six, two absent
      {1 / 6.f, 1 / 6.f, 1 / 6.f, 1 / 6.f, 1 / 6.f, 1 / 6.f},
      {0.05f, 0.1f, 0.15f, 0.2f, 0.25f, 0.05f, 0.1f, 0.03f, 0.04f, 0.03f},  // 10: the generic kernel
  };
  for (DitherMode mode : {DitherMode::fs, DitherMode::stochastic}) {
    for (const auto& f : cases) {
      Layer layer(400, 400, static_cast<int>(f.size()));
      layer.fill(f);
      const auto s = shares(run(layer, mode, {37, 64, 1}, 3, 11), layer.m);
      std::string line = std::string(dither_mode_name(mode)) + ":";
      double worst = 0;
      for (std::size_t k = 0; k < f.size(); ++k) {
        INFO(dither_mode_name(mode) << " material " << k << " fraction " << f[k] << " share " << s[k]);
        CHECK(std::abs(s[k] - f[k]) <= 0.02);
        if (f[k] == 0.0f) CHECK(s[k] == 0.0);  // absent materials never print
        worst = std::max(worst, std::abs(s[k] - f[k]));
        ((line += ' ') += std::to_string(f[k]).substr(0, 6)) += "->";
        line += std::to_string(s[k]).substr(0, 7);
      }
      if (print_shares()) std::cout << line << "  (worst " << worst << ")\n";
    }
  }
}

TEST_CASE("none takes the largest fraction, the lowest index on ties", "[dither]") {
  Layer layer(5, 3, 3);
  layer.fill({0.2f, 0.5f, 0.3f});
  layer.set(1, 1, {0.4f, 0.2f, 0.4f});
  layer.set(2, 2, {0.0f, 0.0f, 1.0f});
  layer.cell[layer.at(4, 0)] = -1;
  const auto out = run(layer, DitherMode::none);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) {
      const int want = x == 4 && y == 0 ? 255 : x == 1 && y == 1 ? 0 : x == 2 && y == 2 ? 2 : 1;
      CHECK(out[layer.at(x, y)] == want);
    }
}

namespace {

/// A layer with smoothly varying 4-material fractions and void holes: a disc, a void column
/// and a void row, so that banding and voids interact.
Layer varied_layer(int nx, int ny) {
  Layer layer(nx, ny, 4);
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x) {
      const float u = static_cast<float>(x) / nx, v = static_cast<float>(y) / ny;
      std::vector<float> f = {u * v, (1 - u) * v, u * (1 - v), (1 - u) * (1 - v)};
      if (x > nx / 2 && y < ny / 3) f = {0.0f, 0.5f, 0.0f, 0.5f};
      layer.set(x, y, f);
      const double dx = x - nx * 0.3, dy = y - ny * 0.6;
      if (dx * dx + dy * dy < 400 || x == nx / 4 || y == ny / 2) layer.cell[layer.at(x, y)] = -1;
    }
  return layer;
}

}  // namespace

TEST_CASE("the output does not depend on how a layer is split into bands", "[dither]") {
  const Layer layer = varied_layer(257, 193);
  for (DitherMode mode : {DitherMode::fs, DitherMode::stochastic, DitherMode::none}) {
    INFO(dither_mode_name(mode));
    const auto whole = run(layer, mode, {1000}, 5, 9);
    CHECK(run(layer, mode, {1}, 5, 9) == whole);
    CHECK(run(layer, mode, {64}, 5, 9) == whole);
    CHECK(run(layer, mode, {3, 1, 17, 2, 50}, 5, 9) == whole);
    CHECK(run(layer, mode, {192, 1}, 5, 9) == whole);
    for (std::size_t i = 0; i < whole.size(); ++i)
      REQUIRE((whole[i] == void_material) == (layer.cell[i] < 0));
  }
}

TEST_CASE("fs: a new layer starts afresh, and the same layer gives the same output", "[dither]") {
  const Layer layer = varied_layer(101, 77);
  LayerDitherer d(DitherMode::fs, layer.nx, layer.m, 0.0423, 0.0847);
  std::vector<std::uint8_t> a(layer.cell.size()), b(layer.cell.size());
  for (int round = 0; round < 2; ++round) {
    d.begin_layer(round);
    d.dither(0, layer.ny, layer.cell.data(), layer.fractions.data(), round == 0 ? a.data() : b.data());
  }
  CHECK(a == b);  // fs ignores the layer number; the state was reset
  CHECK(a == run(layer, DitherMode::fs, {1000}));
  // Rows must not go backwards within a layer; skipped rows are fine.
  CHECK_THROWS_AS(d.dither(10, 1, layer.cell.data(), layer.fractions.data(), b.data()), trivox::Error);
  CHECK_THROWS_AS(d.dither(-1, 1, layer.cell.data(), layer.fractions.data(), b.data()), trivox::Error);
}

TEST_CASE("fs: void voxels neither receive nor pass error", "[dither]") {
  // Left of a void column one composition, right of it another: the right side's output is the
  // same as when everything left of the column is void (nothing crosses the column).
  Layer both(120, 90, 3), right_only(120, 90, 3);
  for (int y = 0; y < 90; ++y)
    for (int x = 0; x < 120; ++x) {
      const bool left = x < 50;
      both.set(x, y, left ? std::vector<float>{0.7f, 0.2f, 0.1f} : std::vector<float>{0.1f, 0.3f, 0.6f});
      right_only.set(x, y, {0.1f, 0.3f, 0.6f});
      if (x == 50) both.cell[both.at(x, y)] = -1;
      if (x <= 50) right_only.cell[right_only.at(x, y)] = -1;
    }
  const auto a = run(both, DitherMode::fs), b = run(right_only, DitherMode::fs);
  for (int y = 0; y < 90; ++y)
    for (int x = 51; x < 120; ++x) REQUIRE(a[both.at(x, y)] == b[both.at(x, y)]);

  // Across a void row: rows below it come out as if the layer began there, and skipping rows
  // between two calls is the same as passing void rows.
  Layer rows(80, 60, 2);
  rows.fill({0.37f, 0.63f});
  for (int x = 0; x < 80; ++x) rows.cell[rows.at(x, 30)] = -1;
  const auto full = run(rows, DitherMode::fs, {7});
  LayerDitherer d(DitherMode::fs, 80, 2, 0.0423, 0.0847);
  d.begin_layer(0);
  std::vector<std::uint8_t> tail(80 * 29);
  d.dither(31, 29, rows.cell.data() + rows.at(0, 31), rows.fractions.data() + rows.at(0, 31) * 2, tail.data());
  CHECK(std::equal(tail.begin(), tail.end(), full.begin() + static_cast<std::ptrdiff_t>(rows.at(0, 31))));
}

TEST_CASE("fs: error from a neighbouring region never prints a material absent here", "[dither]") {
  Layer layer(200, 200, 3);
  for (int y = 0; y < 200; ++y)
    for (int x = 0; x < 200; ++x)
      layer.set(x, y, (x + y) % 97 < 40 ? std::vector<float>{1.0f, 0.0f, 0.0f} : std::vector<float>{0.0f, 0.45f, 0.55f});
  for (DitherMode mode : {DitherMode::fs, DitherMode::stochastic, DitherMode::none}) {
    const auto out = run(layer, mode);
    for (int y = 0; y < 200; ++y)
      for (int x = 0; x < 200; ++x) {
        const bool first = (x + y) % 97 < 40;
        REQUIRE((out[layer.at(x, y)] == 0) == first);
      }
  }
}

TEST_CASE("fs spreads materials evenly; stochastic is as uneven as independent draws", "[dither]") {
  // Share of material 0 in 8 x 4 windows (about square on the 42.3 x 84.7 um voxel). For
  // independent draws its variance is binomial, f (1 - f) / 32; error diffusion carries each
  // voxel's error to its neighbours, so windows deviate far less (blue noise).
  for (const std::vector<float>& f : {std::vector<float>{0.5f, 0.5f}, {0.3f, 0.7f}, {0.1f, 0.9f}, {0.2f, 0.3f, 0.5f}}) {
    Layer layer(400, 400, static_cast<int>(f.size()));
    layer.fill(f);
    for (DitherMode mode : {DitherMode::fs, DitherMode::stochastic}) {
      const auto out = run(layer, mode);
      double sum = 0;
      int windows = 0;
      for (int y0 = 0; y0 < 400; y0 += 4)
        for (int x0 = 0; x0 < 400; x0 += 8, ++windows) {
          int count = 0;
          for (int y = y0; y < y0 + 4; ++y)
            for (int x = x0; x < x0 + 8; ++x) count += out[layer.at(x, y)] == 0;
          const double d = count / 32.0 - f[0];
          sum += d * d;
        }
      const double ratio = sum / windows / (f[0] * (1 - f[0]) / 32);
      INFO(dither_mode_name(mode) << " f0 " << f[0] << ": window variance / binomial " << ratio);
      if (print_shares()) std::cout << dither_mode_name(mode) << " f0 " << f[0] << ": window variance / binomial " << ratio << "\n";
      if (mode == DitherMode::fs)
        CHECK(ratio < 0.25);
      else
        CHECK(std::abs(ratio - 1) < 0.15);  // 5000 windows: the estimate's relative error is ~2 %
    }
  }
}

TEST_CASE("fs: the vector kernels (up to 8 materials) agree with the generic one", "[dither]") {
  // An extra material that is absent everywhere changes nothing (it is never chosen and its
  // error stays 0), but 9 materials run the generic scalar kernel.
  for (int m : {1, 2, 3, 4, 5, 6, 7, 8}) {
    Layer small(131, 67, m), wide(131, 67, 9);
    std::mt19937 rng(static_cast<unsigned>(m));
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int y = 0; y < 67; ++y)
      for (int x = 0; x < 131; ++x) {
        std::vector<float> f(static_cast<std::size_t>(m));
        float sum = 0;
        for (float& v : f) sum += v = u(rng) < 0.3f ? 0.0f : u(rng);
        if (sum == 0) f[0] = sum = 1;
        for (float& v : f) v /= sum;
        if ((x * 7 + y * 3) % 23 == 0) small.cell[small.at(x, y)] = wide.cell[wide.at(x, y)] = -1;
        small.set(x, y, f);
        f.resize(9, 0.0f);
        wide.set(x, y, f);
      }
    INFO(m << " materials");
    CHECK(run(small, DitherMode::fs, {10}) == run(wide, DitherMode::fs, {10}));
  }
}

TEST_CASE("stochastic: deterministic per (seed, layer, row, column), in any row order", "[dither]") {
  const Layer layer = varied_layer(150, 90);
  const auto a = run(layer, DitherMode::stochastic, {64}, 2, 1);
  CHECK(a == run(layer, DitherMode::stochastic, {5}, 2, 1));
  CHECK(a != run(layer, DitherMode::stochastic, {64}, 3, 1));
  CHECK(a != run(layer, DitherMode::stochastic, {64}, 2, 2));
  // Rows in reverse order, one at a time.
  LayerDitherer d(DitherMode::stochastic, layer.nx, layer.m, 0.0423, 0.0847, 1);
  d.begin_layer(2);
  std::vector<std::uint8_t> b(a.size());
  for (int y = layer.ny - 1; y >= 0; --y)
    d.dither(y, 1, layer.cell.data() + layer.at(0, y), layer.fractions.data() + layer.at(0, y) * layer.m,
             b.data() + layer.at(0, y));
  CHECK(a == b);
}

TEST_CASE("dither_paint: one pass of map, dither and paint equals the three steps in turn", "[dither]") {
  // Colour fields (some out of the reachable colours, some NaN, clamped) with void holes and a
  // void row; the default palette runs the fused kernel, a palette with the colour materials
  // elsewhere (and an extra material) the step-by-step path; 5, 7 and 8 materials too.
  const int nx = 173, ny = 41, np = 4;  // properties: density, r, g, b
  std::vector<std::int32_t> cell(static_cast<std::size_t>(nx) * ny, 0);
  std::vector<float> props(cell.size() * np);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-0.1f, 1.1f);
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x) {
      const std::size_t v = static_cast<std::size_t>(y) * nx + x;
      const float s = 0.5f + 0.5f * std::sin(0.05f * x + 0.1f * y);
      props[v * np] = u(rng);
      props[v * np + 1] = (x % 5 == 0) ? u(rng) : s;
      props[v * np + 2] = (x % 17 == 0) ? std::nanf("") : 1.0f - s;
      props[v * np + 3] = (y % 3 == 0) ? u(rng) : 0.5f * s;
      if ((x * 7 + y * 3) % 19 == 0 || y == 20 || (x > 60 && x < 70)) cell[v] = -1;
    }
  Palette moved = default_palette();
  std::swap(moved.materials[0], moved.materials[5]);
  moved.materials.push_back({"Extra", {1, 2, 3, 255}});
  std::vector<Palette> palettes = {default_palette(), moved};
  for (int m : {5, 7, 8}) {
    Palette p = default_palette();
    p.materials.resize(5);
    for (int k = 5; k < m; ++k) p.materials.push_back({"Extra" + std::to_string(k), {std::uint8_t(k), 2, 3, 255}});
    palettes.push_back(p);
  }
  const std::vector<std::string> names = {"density", "r", "g", "b"};
  for (const Palette& palette : palettes)
    for (DitherMode mode : {DitherMode::fs, DitherMode::stochastic, DitherMode::none}) {
      const MaterialMapper mapper(palette, names);
      const int nm = mapper.materials();
      std::array<std::uint32_t, 256> colours{};
      for (int k = 0; k < nm; ++k) std::memcpy(&colours[static_cast<std::size_t>(k)], palette.materials[static_cast<std::size_t>(k)].rgba.data(), 4);
      // The three steps.
      std::vector<float> fr(cell.size() * static_cast<std::size_t>(nm), 0.0f);
      mapper.fractions(props.data(), cell.data(), cell.size(), fr.data());
      LayerDitherer d1(mode, nx, nm, 0.0423, 0.0847);
      d1.begin_layer(3);
      std::vector<std::uint8_t> chosen(cell.size());
      d1.dither(0, ny, cell.data(), fr.data(), chosen.data());
      std::vector<std::uint8_t> want(cell.size() * 4);
      std::vector<std::int64_t> want_counts(static_cast<std::size_t>(nm), 0);
      for (std::size_t v = 0; v < cell.size(); ++v) {
        std::memcpy(want.data() + 4 * v, &colours[chosen[v]], 4);
        if (chosen[v] != void_material) ++want_counts[chosen[v]];
      }
      // One pass, row by row.
      LayerDitherer d2(mode, nx, nm, 0.0423, 0.0847);
      d2.begin_layer(3);
      std::vector<std::uint8_t> got(cell.size() * 4, 9);
      std::vector<std::int64_t> counts(static_cast<std::size_t>(nm), 0);
      for (int y = 0; y < ny; ++y) {
        const std::size_t at = static_cast<std::size_t>(y) * nx;
        d2.dither_paint(y, cell.data() + at, props.data() + at * np, mapper, colours, got.data() + 4 * at, counts.data());
      }
      INFO(nm << " materials, mode " << dither_mode_name(mode) << ", first material " << palette.materials[0].name);
      CHECK(got == want);
      CHECK(counts == want_counts);
    }
}

TEST_CASE("LayerGroupDitherer: each layer of a group equals dithering it alone", "[dither]") {
  // Layers with their own colour fields (some out of reach, some NaN) and their own voids
  // (holes, a void row, void runs, a layer entirely void), in groups of 1 to 8 layers, rows
  // given one at a time with a skipped row; also rows of 1 and 2 voxels. In the shaped cases
  // each layer is a disc of its own centre and radius (some reaching past the row's ends),
  // with holes, so that the columns where any layer of a group is live grow and shrink from row
  // to row (every third row narrower), and some rows are void in every layer (the kernel
  // visits only those columns).
  const std::vector<std::string> names = {"r", "g", "b", "density"};
  const int np = 4;
  if (!LayerGroupDitherer::serves(DitherMode::fs, MaterialMapper(default_palette(), names))) {
    WARN("this CPU has no AVX2: the print job dithers one layer at a time, the grouped kernel is not built for it");
    return;
  }
  // Rows of 300 hold more than 63 live columns (the AVX2 kernel's packed counts unpack midway);
  // on a CPU with AVX-512 both kernels run (TRIVOX_NO_AVX512 picks the AVX2 one).
  struct RestoreKernel {
    ~RestoreKernel() { unsetenv("TRIVOX_NO_AVX512"); }
  } restore;
  struct Case {
    bool avx2_only;  // the AVX2 kernel even where AVX-512 exists
    int nx;          // voxels per row
    bool shaped;     // discs, else scattered voids
  };
  std::vector<Case> cases;
  for (const bool avx2_only : {false, true}) {
    for (const int n : {1, 2, 97, 300}) cases.push_back({avx2_only, n, false});
    for (const int n : {97, 300}) cases.push_back({avx2_only, n, true});
  }
  for (const auto& [avx2_only, nx, shaped] : cases) {
    if (avx2_only) setenv("TRIVOX_NO_AVX512", "1", 1);
    else unsetenv("TRIVOX_NO_AVX512");
    const int ny = 23, layers = 8;
    std::vector<std::vector<std::int32_t>> cell(layers, std::vector<std::int32_t>(static_cast<std::size_t>(nx) * ny, 0));
    std::vector<std::vector<float>> props(layers, std::vector<float>(cell[0].size() * np));
    std::mt19937 rng(11 + nx);
    std::uniform_real_distribution<float> u(-0.1f, 1.1f);
    for (int l = 0; l < layers; ++l)
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) {
          const std::size_t v = static_cast<std::size_t>(y) * nx + x;
          const float s = 0.5f + 0.5f * std::sin(0.07f * x + 0.13f * y + 0.9f * l);
          props[l][v * np] = (x % 7 == l % 7) ? u(rng) : s;
          props[l][v * np + 1] = (x % 13 == 0) ? std::nanf("") : 1.0f - s;
          props[l][v * np + 2] = (y % 4 == l % 4) ? u(rng) : 0.3f * s;
          props[l][v * np + 3] = u(rng);
          if (shaped) {
            const double cx = nx * (0.15 + 0.1 * l), cy = 11.0 + (l % 3) - 1.0, rx = nx * (0.1 + 0.05 * l), ry = 5.0 + l % 4;
            const double q = (x - cx) * (x - cx) / (rx * rx) + (y - cy) * (y - cy) / (ry * ry);
            // Every third row narrower in every layer: the rows after it reach columns whose
            // error half was last written two rows before (and must read as zero).
            const bool narrow = y % 3 == 0 && (3 * x < nx || 3 * x > 2 * nx);
            if (q >= 1.0 || narrow || (x * (l + 3) + y * 5) % 17 == 0) cell[l][v] = -1;
          } else if ((x * (l + 3) + y * 5) % 11 == 0 || y == 9 + l || (x > 20 + 3 * l && x < 30 + 4 * l) || l == 6) {
            cell[l][v] = -1;
          }
        }
    for (const bool five : {false, true}) {
      Palette palette = default_palette();
      if (five) palette.materials.resize(5);
      const MaterialMapper mapper(palette, names);
      REQUIRE(LayerGroupDitherer::serves(DitherMode::fs, mapper));
      const int nm = mapper.materials();
      std::array<std::uint32_t, 256> colours{};
      for (int k = 0; k < nm; ++k) std::memcpy(&colours[static_cast<std::size_t>(k)], palette.materials[static_cast<std::size_t>(k)].rgba.data(), 4);
      auto row_skipped = [](int y) { return y == 15; };
      // Each layer alone.
      std::vector<std::vector<std::uint8_t>> want(layers, std::vector<std::uint8_t>(cell[0].size() * 4, 0));
      std::vector<std::vector<std::int64_t>> want_counts(layers, std::vector<std::int64_t>(static_cast<std::size_t>(nm), 0));
      for (int l = 0; l < layers; ++l) {
        LayerDitherer d(DitherMode::fs, nx, nm, 0.0423, 0.0847);
        d.begin_layer(l);
        for (int y = 0; y < ny; ++y) {
          if (row_skipped(y)) continue;
          const std::size_t at = static_cast<std::size_t>(y) * nx;
          d.dither_paint(y, cell[l].data() + at, props[l].data() + at * np, mapper, colours, want[l].data() + 4 * at,
                         want_counts[l].data());
        }
      }
      LayerGroupDitherer g(nx, mapper, 0.0423, 0.0847);
      for (int size = 1; size <= layers; ++size) {
        // The layers in groups of `size` (the last one smaller).
        std::vector<std::vector<std::uint8_t>> got(layers, std::vector<std::uint8_t>(cell[0].size() * 4, 9));
        std::vector<std::vector<std::int64_t>> got_counts(layers, std::vector<std::int64_t>(static_cast<std::size_t>(nm), 0));
        for (int l0 = 0; l0 < layers; l0 += size) {
          const int n = std::min(size, layers - l0);
          g.begin(n);
          for (int y = 0; y < ny; ++y) {
            if (row_skipped(y)) continue;
            const std::size_t at = static_cast<std::size_t>(y) * nx;
            const std::int32_t* c[8];
            const float* p[8];
            std::uint8_t* o[8];
            std::int64_t* k[8];
            for (int i = 0; i < n; ++i) {
              c[i] = cell[l0 + i].data() + at;
              p[i] = props[l0 + i].data() + at * np;
              o[i] = got[l0 + i].data() + 4 * at;
              k[i] = got_counts[l0 + i].data();
            }
            g.dither_paint(y, c, p, colours, o, k);
          }
        }
        // The same groups as material indices (dither): painted, the same pixels and counts.
        std::vector<std::vector<std::uint8_t>> idx(layers, std::vector<std::uint8_t>(cell[0].size(), 9));
        std::vector<std::vector<std::int64_t>> idx_counts(layers, std::vector<std::int64_t>(static_cast<std::size_t>(nm), 0));
        for (int l0 = 0; l0 < layers; l0 += size) {
          const int n = std::min(size, layers - l0);
          g.begin(n);
          for (int y = 0; y < ny; ++y) {
            if (row_skipped(y)) continue;
            const std::size_t at = static_cast<std::size_t>(y) * nx;
            const std::int32_t* c[8];
            const float* p[8];
            std::uint8_t* o[8];
            std::int64_t* k[8];
            for (int i = 0; i < n; ++i) {
              c[i] = cell[l0 + i].data() + at;
              p[i] = props[l0 + i].data() + at * np;
              o[i] = idx[l0 + i].data() + at;
              k[i] = idx_counts[l0 + i].data();
            }
            g.dither(y, c, p, o, k);
          }
        }
        for (int l = 0; l < layers; ++l) {
          INFO("nx " << nx << (shaped ? " (discs)" : "") << ", " << nm << " materials, groups of " << size << ", layer " << l);
          // Rows skipped stay as they were (9): the same rows are compared.
          for (int y = 0; y < ny; ++y)
            if (row_skipped(y)) {
              std::fill(got[l].begin() + 4 * y * nx, got[l].begin() + 4 * (y + 1) * nx, 0);
              std::fill(idx[l].begin() + y * nx, idx[l].begin() + (y + 1) * nx, void_material);
            }
          CHECK(got[l] == want[l]);
          CHECK(got_counts[l] == want_counts[l]);
          std::vector<std::uint8_t> painted(idx[l].size() * 4);
          bool indices_ok = true;
          for (std::size_t v = 0; v < idx[l].size(); ++v) {
            const bool skipped = row_skipped(static_cast<int>(v) / nx);
            indices_ok = indices_ok && (idx[l][v] < nm || idx[l][v] == void_material) &&
                         (skipped || (idx[l][v] == void_material) == (cell[l][v] < 0));
            std::memcpy(&painted[4 * v], &colours[idx[l][v]], 4);
          }
          CHECK(indices_ok);
          CHECK(painted == want[l]);
          CHECK(idx_counts[l] == want_counts[l]);
        }
      }
    }
  }
  // Bad use.
  const MaterialMapper mapper(default_palette(), names);
  CHECK_THROWS_AS(LayerGroupDitherer(0, mapper, 0.0423, 0.0847), trivox::Error);
  LayerGroupDitherer g(4, mapper, 0.0423, 0.0847);
  CHECK_THROWS_AS(g.begin(0), trivox::Error);
  CHECK_THROWS_AS(g.begin(9), trivox::Error);
  Palette moved = default_palette();
  std::swap(moved.materials[0], moved.materials[5]);
  CHECK_FALSE(LayerGroupDitherer::serves(DitherMode::fs, MaterialMapper(moved, names)));
  CHECK_FALSE(LayerGroupDitherer::serves(DitherMode::stochastic, mapper));
}

TEST_CASE("fs: dithering leaves the caller's floating-point mode as it found it", "[dither]") {
  // The fs paths flush subnormal floats while they run (dither_kernels.hpp, FlushDenormals); the rest
  // of the program must still see them. A product below the smallest normal float is
  // subnormal, not 0, after each kind of call.
  const std::vector<std::string> names = {"r", "g", "b"};
  const MaterialMapper mapper(default_palette(), names);
  const int nx = 16, nm = mapper.materials();
  std::vector<std::int32_t> cell(nx, 0);
  std::vector<float> props(static_cast<std::size_t>(nx) * 3, 0.25f);
  std::vector<float> fractions(static_cast<std::size_t>(nx * nm), 1.0f / static_cast<float>(nm));
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(nx) * 4), idx(nx);
  std::vector<std::int64_t> counts(static_cast<std::size_t>(nm), 0);
  std::array<std::uint32_t, 256> colours{};
  volatile float tiny = std::numeric_limits<float>::min();
  auto subnormal_survives = [&] {
    const float h = tiny * 0.25f;
    return h != 0.0f && std::fpclassify(h) == FP_SUBNORMAL;
  };
  REQUIRE(subnormal_survives());
  LayerDitherer d(DitherMode::fs, nx, nm, 0.0423, 0.0847);
  d.begin_layer(0);
  d.dither(0, 1, cell.data(), fractions.data(), idx.data());
  CHECK(subnormal_survives());
  d.dither_paint(1, cell.data(), props.data(), mapper, colours, rgba.data(), counts.data());
  CHECK(subnormal_survives());
  if (LayerGroupDitherer::serves(DitherMode::fs, mapper)) {
    LayerGroupDitherer g(nx, mapper, 0.0423, 0.0847);
    g.begin(1);
    const std::int32_t* c[1] = {cell.data()};
    const float* p[1] = {props.data()};
    std::uint8_t* o[1] = {rgba.data()};
    std::int64_t* k[1] = {counts.data()};
    g.dither_paint(0, c, p, colours, o, k);
    CHECK(subnormal_survives());
  }
}
