// `trivox preview DIR -o PNG`: a picture of a slice folder for a person (io::write_preview):
// a contact sheet of every n-th slice and a vertical cross-section, in physical proportions.
// Missing or corrupt slices are drawn crossed out and counted, not fatal (`inspect` judges a
// stack); exit 2 when the folder or its ConfigFile.xml is unusable or an option is out of range.
#include <cstdio>

#include "common.hpp"
#include "trivox/io/preview.hpp"

namespace trivox::cli {

namespace {

struct Options {
  std::string dir, output;
  int every = 0, width = 1600;
};

}  // namespace

void add_preview(CLI::App& app, Common& common) {
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("preview", "A contact sheet of slices and a vertical cross-section of a slice folder");
  sub->add_option("DIR", opt->dir, "Slice folder (holding ConfigFile.xml and the PNG slices)")->required();
  sub->add_option("-o,--output", opt->output, "PNG picture to write")->required();
  sub->add_option("--every", opt->every, "Show every N-th slice (default: about 16 slices)");
  sub->add_option("--width", opt->width, "Picture width in pixels, 64..16384 (default 1600)");
  sub->add_flag("--json", common.json, "Print one JSON object instead of the summary");
  sub->callback([opt, &common] {
    const io::PreviewSummary s = io::write_preview(opt->dir, opt->output, opt->every, opt->width);
    if (common.json) {
      print_json({{"path", opt->dir},
                  {"output", opt->output},
                  {"width", s.width},
                  {"height", s.height},
                  {"every", s.every},
                  {"shown", s.shown},
                  {"unreadable", s.unreadable},
                  {"section",
                   {{"row", s.section_row},
                    {"width", s.section_width},
                    {"height", s.section_height},
                    {"z_scale", s.section_z_scale}}}});
      return;
    }
    std::printf("%s: %d x %d px picture of %s\n", opt->output.c_str(), s.width, s.height, opt->dir.c_str());
    std::printf("contact sheet: %zu slices from %d, step %d\n", s.shown.size(), s.shown.empty() ? 0 : s.shown.front(),
                s.every);
    std::printf("cross-section: XZ through image row %d, %d x %d px, %s\n", s.section_row, s.section_width,
                s.section_height,
                s.section_z_scale == 1 ? "true proportions"
                                       : ("z stretched " + std::to_string(s.section_z_scale) + " times").c_str());
    if (!s.unreadable.empty()) {
      std::string l;
      for (int i : s.unreadable) l += (l.empty() ? "" : ", ") + std::to_string(i);
      std::printf("crossed out (missing or corrupt): %s; run trivox inspect for details\n", l.c_str());
    }
  });
}

}  // namespace trivox::cli
