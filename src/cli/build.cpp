// `trivox build SCENE -o MODEL`: expands a scene's primitives (seed 003 Sec. 3.2.3) and fields
// into a model, writes it atomically (save_model: a temporary name, then a rename), and prints a
// quality report: per cell the Jacobian validity bounds and the volume, per primitive the exact
// volume against the cells' total and how closely the properties follow the field. Exit 1 when a
// cell is not valid (the model is written all the same, so it can be inspected).
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "common.hpp"
#include "trivox/error.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/geom/validity.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/io/scene.hpp"
#include "trivox/slice/locator.hpp"
#include "trivox/slice/trim.hpp"

namespace trivox::cli {

namespace {

struct Options {
  std::string scene, output;
  bool force = false;
};

struct CellQuality {
  bool checked = false;  ///< false for a rational trivariate, which check_validity does not decide
  geom::ValidityReport<3> validity;
  double volume = 0.0;
};

nlohmann::ordered_json report(const io::SceneBuild& built, const std::vector<CellQuality>& q, const Options& opt) {
  const auto& cells = built.model.cells;
  std::vector<std::string> source(cells.size());
  for (const auto& p : built.primitives)
    for (int i = 0; i < p.cell_count; ++i) source[static_cast<std::size_t>(p.first_cell + i)] = p.name;
  nlohmann::ordered_json jc = nlohmann::ordered_json::array();
  bool valid = true;
  double total = 0.0;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const auto& r = q[i].validity;
    const bool ok = r.verdict == geom::Validity::valid;
    valid = valid && (ok || !q[i].checked);
    total += q[i].volume;
    jc.push_back({{"name", cells[i].name},
                  {"primitive", source[i].empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(source[i])},
                  {"orders", cells[i].volume.orders()},
                  {"counts", cells[i].volume.counts()},
                  {"valid", q[i].checked ? nlohmann::ordered_json(ok) : nlohmann::ordered_json(nullptr)},
                  {"verdict", q[i].checked ? geom::validity_name(r.verdict) : "unchecked (rational)"},
                  {"min_jacobian", r.min_bound},
                  {"max_jacobian", r.max_bound},
                  {"volume", q[i].volume}});
  }
  nlohmann::ordered_json jp = nlohmann::ordered_json::array();
  for (const auto& p : built.primitives) {
    double v = 0.0;
    for (int i = 0; i < p.cell_count; ++i) v += q[static_cast<std::size_t>(p.first_cell + i)].volume;
    nlohmann::ordered_json field = nullptr;
    if (p.has_field)
      field = {{"exact", p.field.exact},
               {"max_error", p.field.max_error},
               {"refinements", p.field.refinements},
               {"converged", p.field.converged}};
    jp.push_back({{"name", p.name},
                  {"type", p.type},
                  {"cells", p.cell_count},
                  {"exact_volume", p.exact_volume},
                  {"volume", v},
                  {"relative_error", std::abs(v - p.exact_volume) / p.exact_volume},
                  {"field", field}});
  }
  return {{"scene", opt.scene},
          {"model", opt.output},
          {"units", built.model.units},
          {"properties", built.model.properties},
          {"valid", valid},
          {"volume", total},
          {"cells", jc},
          {"primitives", jp}};
}

void print_human(const nlohmann::ordered_json& j) {
  std::printf("%s -> %s: %zu cells, units %s\n", j["scene"].get<std::string>().c_str(),
              j["model"].get<std::string>().c_str(), j["cells"].size(), j["units"].get<std::string>().c_str());
  std::printf("\n%-20s %-10s %15s %15s %15s\n", "cell", "verdict", "min det J", "max det J", "volume");
  for (const auto& c : j["cells"])
    std::printf("%-20s %-10s %15s %15s %15s\n", c["name"].get<std::string>().c_str(),
                c["verdict"].get<std::string>().c_str(), fmt(c["min_jacobian"].get<double>(), 8).c_str(),
                fmt(c["max_jacobian"].get<double>(), 8).c_str(), fmt(c["volume"].get<double>(), 10).c_str());
  if (!j["primitives"].empty()) {
    std::printf("\n%-16s %-9s %6s %15s %15s %10s  %s\n", "primitive", "type", "cells", "exact volume", "volume",
                "rel. error", "field");
    for (const auto& p : j["primitives"]) {
      std::string field = "(none)";
      if (!p["field"].is_null())
        field = p["field"]["exact"].get<bool>()
                    ? "exact"
                    : "max error " + fmt(p["field"]["max_error"].get<double>(), 3) + " of the range after " +
                          std::to_string(p["field"]["refinements"].get<int>()) + " refinements" +
                          (p["field"]["converged"].get<bool>() ? "" : " (above 1/512: a kink the cells cannot follow)");
      std::printf("%-16s %-9s %6d %15s %15s %10s  %s\n", p["name"].get<std::string>().c_str(),
                  p["type"].get<std::string>().c_str(), p["cells"].get<int>(),
                  fmt(p["exact_volume"].get<double>(), 10).c_str(), fmt(p["volume"].get<double>(), 10).c_str(),
                  fmt(p["relative_error"].get<double>(), 3).c_str(), field.c_str());
    }
  }
  std::printf("\ntotal volume %s; %s\n", fmt(j["volume"].get<double>(), 12).c_str(),
              j["valid"].get<bool>() ? "every cell is valid" : "NOT every cell is valid");
}

}  // namespace

void add_build(CLI::App& app, Common& common) {
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "build", "Turn a scene (primitives with fields, trivariates) into a model, with a quality report");
  sub->add_option("SCENE", opt->scene, "Scene file (.json)")->required();
  sub->add_option("-o,--output", opt->output, "Model file to write (.json)")->required();
  sub->add_flag("--force", opt->force, "Replace MODEL if it exists");
  sub->add_flag("--json", common.json, "Print one JSON object instead of the report");
  sub->callback([opt, &common] {
    std::error_code ec;
    if (!opt->force && std::filesystem::exists(opt->output, ec))
      throw Error(opt->output + ": the file exists; expected a new model file name, or --force to replace it");
    const io::Scene scene = io::load_scene(opt->scene);
    const io::SceneBuild built = io::build_scene(scene);
    // Each cell's geometry: a primitive's before its field refined it (the same map).
    std::vector<const spline::Trivariate*> geometry;
    for (const auto& c : built.model.cells) geometry.push_back(&c.volume);
    for (const auto& p : built.primitives)
      for (int i = 0; i < p.cell_count; ++i)
        geometry[static_cast<std::size_t>(p.first_cell + i)] = &p.geometry[static_cast<std::size_t>(i)];
    std::vector<CellQuality> q(geometry.size());
    tbb::parallel_for(std::size_t{0}, geometry.size(), [&](std::size_t i) {
      // Rational trivariate cells have no Bezier-bound verdict (geom/validity.hpp): reported
      // as unchecked, not as invalid.
      q[i].checked = !geometry[i]->rational();
      if (q[i].checked) q[i].validity = geom::check_validity(*geometry[i]);
      q[i].volume = geom::volume(*geometry[i]);
    });
    // Pieces of Booleans: the volume of the part their trimming admits (slice/trim.hpp).
    bool trimmed = false;
    for (const auto& c : built.model.cells) trimmed = trimmed || !c.plain();
    if (trimmed) {
      const slice::Locator loc(built.model, {.tolerance = 1e-9 * slice::model_diagonal(built.model)});
      tbb::parallel_for(std::size_t{0}, geometry.size(), [&](std::size_t i) {
        if (!built.model.cells[i].plain()) q[i].volume = slice::trimmed_volume(loc, static_cast<int>(i));
      });
    }
    io::save_model(built.model, opt->output);
    const auto j = report(built, q, *opt);
    if (common.json)
      print_json(j);
    else
      print_human(j);
    if (!j["valid"].get<bool>()) common.exit_code = 1;
  });
}

}  // namespace trivox::cli
