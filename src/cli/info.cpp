// `trivox info MODEL`: what a model holds: cells with orders, control-point counts, bounding box
// and volume (Gauss quadrature of the Jacobian determinant, exact for polynomial cells; for the
// trimmed pieces of Booleans the divergence theorem on their untrimmed boundary faces,
// slice/piece_measures.hpp, or sampling where that is refused), free surfaces, properties and
// topology counts; the integral of every property over every cell (slice/property_integrals.hpp)
// and their totals.
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>

#include "common.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/slice/locator.hpp"
#include "trivox/slice/piece_measures.hpp"
#include "trivox/slice/property_integrals.hpp"
#include "trivox/slice/trim.hpp"
#include "trivox/spline/extract.hpp"
#include "trivox/vmodel/topology.hpp"

namespace trivox::cli {

namespace {

struct Options {
  std::string model;
};

template <int P>
nlohmann::ordered_json spline_summary(const std::string& name, const spline::TensorSpline<P>& s) {
  const auto box = spline::bounding_box(s, 3);
  return {{"name", name},
          {"orders", s.orders()},
          {"counts", s.counts()},
          {"rational", s.rational()},
          {"bbox", {box[0], box[1]}}};
}

bool any_trimmed_cell(const vmodel::VModel& m) {
  for (const auto& c : m.cells)
    if (!c.plain()) return true;
  return false;
}

nlohmann::ordered_json summarise(const vmodel::VModel& m, const std::string& file) {
  nlohmann::ordered_json cells = nlohmann::ordered_json::array();
  std::vector<double> volumes(m.cells.size());
  tbb::parallel_for(std::size_t{0}, m.cells.size(), [&](std::size_t i) { volumes[i] = geom::signed_volume(m.cells[i].volume); });
  // Cells trimmed by Booleans: the volume of the admitted part from its boundary faces
  // (slice/piece_measures.hpp, exact), or by sampling (slice/trim.hpp) where those are refused.
  std::vector<char> trimmed(m.cells.size(), 0);
  bool any_trimmed = false;
  for (std::size_t i = 0; i < m.cells.size(); ++i) {
    trimmed[i] = !m.cells[i].plain();
    any_trimmed = any_trimmed || trimmed[i];
  }
  std::vector<std::optional<slice::PieceMeasures>> exact(m.cells.size());
  std::vector<std::string> refused(m.cells.size());
  if (any_trimmed) {
    tbb::parallel_for(std::size_t{0}, m.cells.size(), [&](std::size_t i) {
      if (!trimmed[i]) return;
      try {
        exact[i] = slice::piece_measures(m, static_cast<int>(i));
      } catch (const std::exception& e) {
        refused[i] = e.what();
      }
    });
    bool sample = false;
    for (std::size_t i = 0; i < m.cells.size(); ++i) sample = sample || (trimmed[i] && !exact[i]);
    if (sample) {
      const slice::Locator loc(m, {.tolerance = 1e-9 * slice::model_diagonal(m)});
      tbb::parallel_for(std::size_t{0}, m.cells.size(), [&](std::size_t i) {
        if (trimmed[i] && !exact[i])
          volumes[i] = (volumes[i] < 0 ? -1.0 : 1.0) * slice::trimmed_volume(loc, static_cast<int>(i));
      });
    }
    for (std::size_t i = 0; i < m.cells.size(); ++i)
      if (exact[i]) volumes[i] = (volumes[i] < 0 ? -1.0 : 1.0) * exact[i]->volume;
  }
  // int rho_k dV per cell: exact for plain polynomial cells and for trimmed pieces of affine
  // trivariates whose boundary measures succeeded; otherwise not computed, with the reason.
  std::vector<slice::PropertyIntegrals> integrals(m.cells.size());
  if (!m.properties.empty())
    tbb::parallel_for(std::size_t{0}, m.cells.size(), [&](std::size_t i) {
      if (trimmed[i] && !exact[i]) {
        integrals[i].note = "its boundary measures were refused";
        return;
      }
      try {
        integrals[i] = slice::property_integrals(m, static_cast<int>(i));
      } catch (const std::exception& e) {
        integrals[i] = {};
        integrals[i].note = e.what();
      }
    });
  std::vector<double> total_integrals(m.properties.size(), 0.0);
  bool all_integrals = !m.properties.empty(), all_exact = true;
  double total = 0;
  std::vector<double> lo(3, std::numeric_limits<double>::infinity()), hi(3, -std::numeric_limits<double>::infinity());
  auto grow = [&](const nlohmann::ordered_json& bbox) {
    for (std::size_t h = 0; h < 3; ++h) {
      lo[h] = std::min(lo[h], bbox[0][h].get<double>());
      hi[h] = std::max(hi[h], bbox[1][h].get<double>());
    }
  };
  for (std::size_t i = 0; i < m.cells.size(); ++i) {
    auto c = spline_summary(m.cells[i].name, m.cells[i].volume);
    c["volume"] = std::abs(volumes[i]);
    c["orientation"] = volumes[i] < 0 ? "left-handed" : "right-handed";
    if (trimmed[i]) {
      c["trimmed"] = true;
      if (const auto& e = exact[i]) {
        c["volume_method"] = "boundary";
        nlohmann::ordered_json piece = {{"empty", e->empty}, {"boundary_area", e->area}, {"faces", e->faces},
                                        {"patches", e->patches}};
        if (!e->empty) {
          piece["centroid"] = e->centroid;
          piece["bbox"] = e->bbox;
          piece["closure"] = e->closure;
          piece["spread"] = e->spread;
        }
        c["piece"] = std::move(piece);
      } else {
        c["volume_method"] = "sampled";
        c["volume_note"] = "16^3 sub-boxes x 8 Gauss points, membership per point; boundary measures refused: " + refused[i];
      }
    }
    if (!m.properties.empty()) {
      const auto& pi = integrals[i];
      if (pi.values.size() == m.properties.size()) {
        nlohmann::ordered_json v = nlohmann::ordered_json::object();
        for (std::size_t k = 0; k < m.properties.size(); ++k) {
          v[m.properties[k]] = pi.values[k];
          total_integrals[k] += pi.values[k];
        }
        c["property_integrals"] = std::move(v);
        c["property_integrals_method"] = pi.method;
        c["property_integrals_exact"] = pi.exact;
        all_exact = all_exact && pi.exact;
      } else {
        c["property_integrals"] = nullptr;
        c["property_integrals_note"] = "not computed: " + pi.note;
        all_integrals = false;
      }
    }
    total += std::abs(volumes[i]);
    grow(c["bbox"]);
    cells.push_back(std::move(c));
  }
  nlohmann::ordered_json surfaces = nlohmann::ordered_json::array();
  for (const auto& s : m.surfaces) {
    auto j = spline_summary(s.name, s.surface);
    grow(j["bbox"]);
    surfaces.push_back(std::move(j));
  }
  nlohmann::ordered_json out = {{"file", file},
                        {"units", m.units},
                        {"properties", m.properties},
                        {"cells", cells},
                        {"surfaces", surfaces},
                        {"volume", total}};
  if (all_integrals && !m.cells.empty()) {
    nlohmann::ordered_json v = nlohmann::ordered_json::object();
    for (std::size_t k = 0; k < m.properties.size(); ++k) v[m.properties[k]] = total_integrals[k];
    out["property_integrals"] = std::move(v);
    out["property_integrals_exact"] = all_exact;
  } else {
    out["property_integrals"] = nullptr;  // no properties, or some cell's not computed
  }
  if (!m.cells.empty() || !m.surfaces.empty()) out["bbox"] = {lo, hi};
  else out["bbox"] = nullptr;
  const auto topo = vmodel::counts(vmodel::build_topology(m));
  if (any_trimmed_cell(m)) out["topology_note"] = "counted on the trivariates of trimmed cells, not on their trimmed parts";
  out["topology"] = {{"v_cells", topo.v_cells},
                     {"v_surfaces", topo.v_surfaces},
                     {"half_v_surfaces", topo.half_v_surfaces},
                     {"v_curves", topo.v_curves},
                     {"v_points", topo.v_points}};
  return out;
}

std::string vec(const nlohmann::ordered_json& a) {
  std::string s = "(";
  for (std::size_t i = 0; i < a.size(); ++i) s += (i ? ", " : "") + (a[i].is_number_float() ? fmt(a[i].get<double>(), 6) : a[i].dump());
  return s + ")";
}

void print_human(const nlohmann::ordered_json& j) {
  std::printf("%s: %zu cells, %zu surfaces, units %s\n", j["file"].get<std::string>().c_str(), j["cells"].size(),
              j["surfaces"].size(), j["units"].get<std::string>().c_str());
  std::string props;
  for (const auto& p : j["properties"]) props += (props.empty() ? "" : ", ") + p.get<std::string>();
  std::printf("properties: %s\n", props.empty() ? "(none)" : props.c_str());
  if (!j["bbox"].is_null()) std::printf("bounding box: %s - %s\n", vec(j["bbox"][0]).c_str(), vec(j["bbox"][1]).c_str());
  if (!j["cells"].empty()) {
    std::printf("\n%-16s %-10s %-13s %-14s %s\n", "cell", "orders", "counts", "volume", "bounding box");
    for (const auto& c : j["cells"])
      std::printf("%-16s %-10s %-13s %-14s %s - %s%s\n", c["name"].get<std::string>().c_str(), vec(c["orders"]).c_str(),
                  vec(c["counts"]).c_str(), fmt(c["volume"].get<double>(), 10).c_str(), vec(c["bbox"][0]).c_str(),
                  vec(c["bbox"][1]).c_str(), c["rational"].get<bool>() ? "  rational" : "");
    std::printf("total volume: %s\n", fmt(j["volume"].get<double>(), 12).c_str());
    int boundary = 0, sampled = 0;
    for (const auto& c : j["cells"])
      if (c.contains("volume_method")) ++(c["volume_method"] == "boundary" ? boundary : sampled);
    if (boundary + sampled > 0)
      std::printf("trimmed cells: %d measured on their boundary faces (exact), %d sampled (approximate)\n", boundary, sampled);
    if (!j["property_integrals"].is_null()) {
      std::string pi;
      for (const auto& [k, v] : j["property_integrals"].items()) pi += (pi.empty() ? "" : ", ") + k + " " + fmt(v.get<double>(), 10);
      std::printf("property integrals (int p dV)%s: %s\n", j["property_integrals_exact"].get<bool>() ? "" : ", not exact", pi.c_str());
    } else {
      int missing = 0;
      for (const auto& c : j["cells"]) missing += c.contains("property_integrals_note") ? 1 : 0;
      if (missing > 0) std::printf("property integrals: not computed for %d cell%s (see --json)\n", missing, missing == 1 ? "" : "s");
    }
  }
  if (!j["surfaces"].empty()) {
    std::printf("\n%-16s %-10s %-13s %s\n", "surface", "orders", "counts", "bounding box");
    for (const auto& c : j["surfaces"])
      std::printf("%-16s %-10s %-13s %s - %s%s\n", c["name"].get<std::string>().c_str(), vec(c["orders"]).c_str(),
                  vec(c["counts"]).c_str(), vec(c["bbox"][0]).c_str(), vec(c["bbox"][1]).c_str(),
                  c["rational"].get<bool>() ? "  rational" : "");
  }
  std::string topo;
  for (const auto& [k, v] : j["topology"].items()) topo += (topo.empty() ? "" : ", ") + k + " " + v.dump();
  std::printf("\ntopology: %s\n", topo.c_str());
}

}  // namespace

void add_info(CLI::App& app, Common& common) {
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("info", "Cells, orders, control points, properties, bounding box, volume, topology");
  sub->add_option("MODEL", opt->model, "Model file (.json, or G+Smo .xml)")->required();
  sub->add_flag("--json", common.json, "Print one JSON object instead of the summary");
  sub->callback([opt, &common] {
    const auto model = io::load_model(opt->model);
    const auto j = summarise(model, opt->model);
    if (common.json)
      print_json(j);
    else
      print_human(j);
  });
}

}  // namespace trivox::cli
