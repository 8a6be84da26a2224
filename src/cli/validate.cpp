// `trivox validate MODEL`: Jacobian validity per cell (geom/validity.hpp), the cells checked in
// parallel. Exit 1 when a cell is neither valid nor degenerate (invalid or undecided).
#include <tbb/parallel_for.h>

#include <cstdio>
#include <exception>
#include <vector>

#include "common.hpp"
#include "trivox/error.hpp"
#include "trivox/geom/validity.hpp"
#include "trivox/io/model_file.hpp"

namespace trivox::cli {

namespace {
struct Options {
  std::string model;
};
}  // namespace

void add_validate(CLI::App& app, Common& common) {
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "validate", "Jacobian validity per cell: bounds of the determinant, first invalid location, degenerate boundaries (exit 1 if any is not valid)");
  sub->add_option("MODEL", opt->model, "Model file (.json, or G+Smo .xml)")->required();
  sub->add_flag("--json", common.json, "Print one JSON object instead of the summary");
  sub->callback([opt, &common] {
    const auto model = io::load_model(opt->model);
    nlohmann::ordered_json cells = nlohmann::ordered_json::array();
    bool all_valid = true;
    if (!common.json)
      std::printf("%-16s %-10s %-12s %15s %15s\n", "cell", "verdict", "orientation", "min det J", "max det J");
    // The cells in parallel (a thousand-span fillet cell takes tens of seconds), reported in order;
    // the first failing cell in file order is the one named.
    const std::size_t n = model.cells.size();
    std::vector<geom::ValidityReport<3>> reports(n);
    std::vector<std::exception_ptr> failed(n);
    tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
      try {
        reports[i] = geom::check_validity(model.cells[i].volume);
      } catch (...) {
        failed[i] = std::current_exception();
      }
    });
    for (std::size_t i = 0; i < n; ++i)
      if (failed[i]) {
        try {
          std::rethrow_exception(failed[i]);
        } catch (const Error& e) {
          throw e.within(opt->model + ": cell " + model.cells[i].name);
        }
      }
    for (std::size_t i = 0; i < n; ++i) {
      const auto& c = model.cells[i];
      const geom::ValidityReport<3>& r = reports[i];
      // A degenerate boundary (det J = 0 there by construction: fillet rails, apexes) leaves the
      // open cell a valid parametrisation: it counts as valid, and is reported as such.
      const bool valid = r.verdict == geom::Validity::valid || r.verdict == geom::Validity::degenerate;
      all_valid = all_valid && valid;
      nlohmann::ordered_json j = {{"name", c.name},
                                  {"valid", valid},
                                  {"min_jacobian", r.min_bound},
                                  {"max_jacobian", r.max_bound},
                                  {"verdict", geom::validity_name(r.verdict)},
                                  {"orientation", r.orientation > 0 ? "right-handed" : r.orientation < 0 ? "left-handed" : "singular"},
                                  {"min_evaluated", r.min_seen},
                                  {"max_evaluated", r.max_seen},
                                  {"pieces", r.pieces}};
      std::string where, degenerate;
      if (r.degenerate_at) {
        const auto& t = *r.degenerate_at;
        const auto x = c.volume.eval(t);
        j["degenerate_at"] = {{"uvw", t}, {"xyz", {x[0], x[1], x[2]}}};
        j["zero_tolerance"] = r.zero_tolerance;
        degenerate = "det J = 0 (within " + fmt(r.zero_tolerance, 3) + ") on the boundary, e.g. at (u,v,w) = (" +
                     fmt(t[0], 8) + ", " + fmt(t[1], 8) + ", " + fmt(t[2], 8) + "), xyz (" + fmt(x[0], 8) + ", " +
                     fmt(x[1], 8) + ", " + fmt(x[2], 8) + "); det J > 0 inside";
      }
      if (r.invalid_at) {
        const auto& t = *r.invalid_at;
        const auto x = c.volume.eval(t);
        j["invalid_at"] = {{"uvw", t}, {"xyz", {x[0], x[1], x[2]}}, {"det", r.det_at_invalid}};
        where = "det J = " + fmt(r.det_at_invalid, 6) + " at (u,v,w) = (" + fmt(t[0], 8) + ", " + fmt(t[1], 8) + ", " +
                fmt(t[2], 8) + "), xyz (" + fmt(x[0], 8) + ", " + fmt(x[1], 8) + ", " + fmt(x[2], 8) + ")";
      }
      cells.push_back(j);
      if (!common.json) {
        std::printf("%-16s %-10s %-12s %15s %15s\n", c.name.c_str(), geom::validity_name(r.verdict),
                    r.orientation > 0 ? "right" : r.orientation < 0 ? "left" : "singular", fmt(r.min_bound, 8).c_str(),
                    fmt(r.max_bound, 8).c_str());
        if (!where.empty()) std::printf("  first invalid point: %s\n", where.c_str());
        if (r.verdict == geom::Validity::degenerate) std::printf("  %s\n", degenerate.c_str());
        if (r.verdict == geom::Validity::undecided)
          std::printf("  det J comes within [%s, %s] of 0 without being seen to reach it\n", fmt(r.min_bound, 6).c_str(),
                      fmt(r.max_bound, 6).c_str());
      }
    }
    if (common.json) print_json({{"valid", all_valid}, {"cells", cells}});
    else std::printf("%s: %s\n", opt->model.c_str(), all_valid ? "every cell is valid" : "NOT every cell is valid");
    if (!all_valid) common.exit_code = 1;
  });
}

}  // namespace trivox::cli
