// `trivox eval MODEL --cell NAME --uvw U,V,W`: the point of a cell at a parameter, with its
// properties (and, with --derivatives, the first partials).
#include <cstdio>

#include "common.hpp"
#include "trivox/error.hpp"
#include "trivox/io/model_file.hpp"

namespace trivox::cli {

namespace {
struct Options {
  std::string model, cell, uvw;
  bool derivatives = false;
};
}  // namespace

void add_eval(CLI::App& app, Common& common) {
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("eval", "The point and properties of a cell at parameters (u,v,w)");
  sub->add_option("MODEL", opt->model, "Model file (.json, or G+Smo .xml)")->required();
  sub->add_option("--cell", opt->cell, "Name of the cell")->required();
  sub->add_option("--uvw", opt->uvw, "Parameters U,V,W inside the cell's domain")->required();
  sub->add_flag("--derivatives", opt->derivatives, "Also print the partial derivatives d/du, d/dv, d/dw");
  sub->add_flag("--json", common.json, "Print one JSON object instead of the summary");
  sub->callback([opt, &common] {
    const auto model = io::load_model(opt->model);
    const auto* cell = model.find_cell(opt->cell);
    if (!cell) {
      std::string names;
      for (const auto& c : model.cells) names += (names.empty() ? "" : ", ") + c.name;
      throw Error(opt->model + ": --cell " + opt->cell + ": no such cell; expected one of: " +
                  (names.empty() ? std::string("(the model has no cells)") : names));
    }
    const auto p = parse_numbers(opt->uvw, 3, "--uvw");
    const auto& s = cell->volume;
    static constexpr const char* axis = "uvw";
    for (int d = 0; d < 3; ++d) {
      const auto dom = s.domain(d);
      if (!(p[static_cast<std::size_t>(d)] >= dom[0] && p[static_cast<std::size_t>(d)] <= dom[1]))
        throw Error(opt->model + ": --uvw " + opt->uvw + ": " + axis[d] + " = " + fmt(p[static_cast<std::size_t>(d)], 17) +
                    " is outside cell " + opt->cell + "'s domain; expected " + fmt(dom[0], 17) + " <= " + axis[d] +
                    " <= " + fmt(dom[1], 17));
    }
    const auto v = s.eval_derivatives({p[0], p[1], p[2]}, opt->derivatives ? 1 : 0);
    const auto k = static_cast<std::size_t>(s.dim());
    nlohmann::ordered_json props = nlohmann::ordered_json::object();
    for (std::size_t i = 0; i < model.properties.size(); ++i) props[model.properties[i]] = v[3 + i];
    nlohmann::ordered_json j = {{"cell", opt->cell}, {"uvw", p}, {"point", {v[0], v[1], v[2]}}, {"properties", props}};
    if (opt->derivatives)
      for (std::size_t d = 0; d < 3; ++d)
        j["derivatives"][std::string(1, axis[d])] = std::vector<double>(v.begin() + static_cast<std::ptrdiff_t>((d + 1) * k),
                                                                         v.begin() + static_cast<std::ptrdiff_t>((d + 2) * k));
    if (common.json) return print_json(j);
    std::printf("cell %s at (u, v, w) = (%s, %s, %s)\n", opt->cell.c_str(), fmt(p[0]).c_str(), fmt(p[1]).c_str(), fmt(p[2]).c_str());
    std::printf("point: (%s, %s, %s)\n", fmt(v[0], 15).c_str(), fmt(v[1], 15).c_str(), fmt(v[2], 15).c_str());
    for (std::size_t i = 0; i < model.properties.size(); ++i)
      std::printf("%s: %s\n", model.properties[i].c_str(), fmt(v[3 + i], 15).c_str());
    if (opt->derivatives)
      for (std::size_t d = 0; d < 3; ++d) {
        std::printf("d/d%c:", axis[d]);
        for (std::size_t h = 0; h < k; ++h) std::printf(" %s", fmt(v[(d + 1) * k + h], 12).c_str());
        std::printf("\n");
      }
  });
}

}  // namespace trivox::cli
