// `trivox locate MODEL --xyz X,Y,Z`: which cell contains a point, at which (u,v,w), and the
// model's properties there (slice/locator.hpp).
#include <cstdio>

#include "common.hpp"
#include "trivox/error.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/fillet/shepard.hpp"
#include "trivox/slice/locator.hpp"
#include "trivox/slice/sampler.hpp"

namespace trivox::cli {

namespace {
struct Options {
  std::string model, xyz, blend = "encoded";
  double tolerance = 1e-6;
};
}  // namespace

void add_locate(CLI::App& app, Common& common) {
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("locate", "Which cell contains a point, at which (u,v,w), and its properties");
  sub->add_option("MODEL", opt->model, "Model file (.json, or G+Smo .xml)")->required();
  sub->add_option("--xyz", opt->xyz, "The point X,Y,Z in model units")->required();
  sub->add_option("--tolerance", opt->tolerance, "Distance in model units within which a point counts as on the cell")
      ->capture_default_str();
  sub->add_option("--blend", opt->blend,
                  "Shepard fillet cells: encoded (their control points, default) or shepard (the exact blend at the point)");
  sub->add_flag("--json", common.json, "Print one JSON object instead of the summary");
  sub->callback([opt, &common] {
    const auto model = io::load_model(opt->model);
    const auto p = parse_numbers(opt->xyz, 3, "--xyz");
    slice::PropertyBlend blend{};
    if (!slice::property_blend_from_name(opt->blend, blend))
      throw Error("--blend " + opt->blend + ": unknown; expected encoded or shepard");
    if (!(opt->tolerance > 0.0 && opt->tolerance < 1e300))
      throw Error("--tolerance " + fmt(opt->tolerance, 17) + ": expected a positive finite distance");
    if (model.cells.empty())
      throw Error(opt->model + ": the model has no cells; expected at least one volumetric cell to locate in");
    slice::LocatorOptions lo;
    lo.tolerance = opt->tolerance;
    const slice::Locator locator(model, lo);
    const slice::Vec3 q{p[0], p[1], p[2]};
    const auto r = locator.locate(q);

    nlohmann::ordered_json j;
    j["inside"] = r.inside;
    j["cell"] = nullptr;
    j["uvw"] = nullptr;
    j["point"] = nullptr;
    j["properties"] = nullptr;
    std::vector<double> x(3), props(model.properties.size());
    if (r.inside) {
      // The cell's own evaluation, so the values equal `trivox eval` at this (u,v,w).
      const auto v = model.cells[static_cast<std::size_t>(r.cell)].volume.eval_derivatives(r.uvw, 0);
      std::copy(v.begin(), v.begin() + 3, x.begin());
      std::copy(v.begin() + 3, v.end(), props.begin());
      // A Boolean's intersection cell blends its inputs' properties (VCell::blend).
      if (!props.empty()) locator.admits(r.cell, q, props.data());
      // A Shepard fillet cell: f itself (Masalha et al. 2021, Sec. 7.2), cold closest points.
      const auto& sd = model.cells[static_cast<std::size_t>(r.cell)].shepard;
      if (blend == slice::PropertyBlend::shepard && sd && !props.empty()) {
        const auto v = vmodel::ShepardField(*sd).eval(q, props.data());
        j["shepard"] = {{"alpha", v.alpha}, {"distance", v.distance}};
      }
      j["cell"] = model.cells[static_cast<std::size_t>(r.cell)].name;
      j["uvw"] = r.uvw;
      j["point"] = x;
      nlohmann::ordered_json pj = nlohmann::ordered_json::object();
      for (std::size_t i = 0; i < props.size(); ++i) pj[model.properties[i]] = props[i];
      j["properties"] = pj;
    }
    j["query"] = p;
    j["converged"] = r.converged;
    if (common.json) return print_json(j);
    std::printf("point (%s, %s, %s): ", fmt(p[0]).c_str(), fmt(p[1]).c_str(), fmt(p[2]).c_str());
    if (!r.inside) {
      std::printf("outside every cell%s\n", r.converged ? "" : " (best guess: some inversion did not converge)");
      return;
    }
    std::printf("inside cell %s at (u, v, w) = (%s, %s, %s)%s\n", model.cells[static_cast<std::size_t>(r.cell)].name.c_str(),
                fmt(r.uvw[0], 15).c_str(), fmt(r.uvw[1], 15).c_str(), fmt(r.uvw[2], 15).c_str(),
                r.converged ? "" : " (best guess: the inversion did not converge)");
    std::printf("cell point: (%s, %s, %s)\n", fmt(x[0], 15).c_str(), fmt(x[1], 15).c_str(), fmt(x[2], 15).c_str());
    for (std::size_t i = 0; i < props.size(); ++i) std::printf("%s: %s\n", model.properties[i].c_str(), fmt(props[i], 15).c_str());
  });
}

}  // namespace trivox::cli
