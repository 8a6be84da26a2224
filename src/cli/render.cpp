// `trivox render FILE.vdb -o PNG`: a picture of a volume (io::render_vdb): density and colour
// composited front to back along parallel rays, seen from an axis or isometrically. Exit 2 for a
// file that is not a readable VDB, a bad option, or an existing picture without --force.
#include <cmath>
#include <cstdio>

#include "common.hpp"
#include "trivox/error.hpp"
#include "trivox/io/vdb_inspect.hpp"

namespace trivox::cli {

namespace {

struct Options {
  std::string file, output, view = "iso", size, background = "255,255,255";
  bool force = false;
};

std::array<std::uint8_t, 4> parse_background(const std::string& text) {
  if (text == "transparent") return {0, 0, 0, 0};
  std::vector<double> v;
  try {
    v = parse_numbers(text, 3, "--background");
  } catch (const Error&) {
    throw Error("--background " + text + ": expected three integers 0..255 \"R,G,B\" or \"transparent\"");
  }
  std::array<std::uint8_t, 4> out{0, 0, 0, 255};
  for (std::size_t i = 0; i < 3; ++i) {
    if (v[i] < 0 || v[i] > 255 || v[i] != std::floor(v[i]))
      throw Error("--background " + text + ": expected three integers 0..255 \"R,G,B\" or \"transparent\"");
    out[i] = static_cast<std::uint8_t>(v[i]);
  }
  return out;
}

}  // namespace

void add_render(CLI::App& app, Common& common) {
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("render", "A picture of a VDB volume: density and colour seen along parallel rays");
  sub->add_option("FILE", opt->file, "OpenVDB file (.vdb), e.g. from trivox slice --vdb")->required();
  sub->add_option("-o,--output", opt->output, "PNG picture to write")->required();
  sub->add_option("--view", opt->view, "Seen from +z, -z, +x, -x, +y, -y or iso (default; from +x, -y, +z)");
  sub->add_option("--size", opt->size, "Picture size W,H in pixels, 16..16384 (default: 800 on the longer side)");
  sub->add_option("--background", opt->background, "Background R,G,B (0..255, default 255,255,255) or transparent");
  sub->add_flag("--force", opt->force, "Replace an existing picture");
  sub->add_flag("--json", common.json, "Print one JSON object instead of the summary");
  sub->callback([opt, &common] {
    io::RenderOptions ro;
    ro.view = opt->view;
    ro.force = opt->force;
    ro.background = parse_background(opt->background);
    if (!opt->size.empty()) {
      const auto s = parse_numbers(opt->size, 2, "--size");
      for (double v : s)
        if (v != std::floor(v) || v < 16 || v > 16384)
          throw Error("--size " + opt->size + ": expected two whole numbers of pixels W,H, each 16 to 16384");
      ro.width = static_cast<int>(s[0]);
      ro.height = static_cast<int>(s[1]);
    }
    const io::RenderSummary s = io::render_vdb(opt->file, opt->output, ro);
    if (common.json) {
      print_json({{"path", opt->file},
                  {"output", opt->output},
                  {"width", s.width},
                  {"height", s.height},
                  {"view", s.view},
                  {"density_grid", s.density_grid},
                  {"color_grid", s.color_grid.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(s.color_grid)},
                  {"covered_pixels", s.covered_pixels}});
      return;
    }
    std::printf("%s: %d x %d px picture of %s, seen from %s\n", opt->output.c_str(), s.width, s.height,
                opt->file.c_str(), s.view.c_str());
    std::printf("grids: density %s, colour %s; %lld pixels covered\n", s.density_grid.c_str(),
                s.color_grid.empty() ? "(none: drawn grey)" : s.color_grid.c_str(),
                static_cast<long long>(s.covered_pixels));
  });
}

}  // namespace trivox::cli
