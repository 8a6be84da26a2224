// `trivox build SCENE -o MODEL`: expands a scene's primitives (Massarwi & Elber 2016, Sec. 3.2.3)
// and fields into a model, writes it atomically (save_model: a temporary name, then a rename), and
// prints a quality report: per cell the Jacobian validity bounds and the volume, per primitive the
// exact volume against the cells' total and how closely the properties follow the field, per fillet
// (ruled, Masalha et al. 2021, Alg. 2, VBS, Sec. 3.2 / Alg. 3, or V-rep, Sec. 5 / Alg. 6) its gap,
// C0 glue between its cells, G1 angle, sampled det J sign and property jump (fillet/fillet.hpp).
// Exit 1 when a cell is not valid (the model is written all the same, so it can be inspected).
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
#include "trivox/scene/scene.hpp"
#include "trivox/slice/locator.hpp"
#include "trivox/slice/piece_measures.hpp"
#include "trivox/slice/trim.hpp"

namespace trivox::cli {

namespace {

struct Options {
  std::string scene, output;
  bool force = false;
};

struct CellQuality {
  bool checked = false;  ///< false for a rational trivariate, which check_validity does not decide
  /// A fillet's half: det J vanishes on the faces that collapse onto the rails (Masalha et al.
  /// 2021, Sec. 9), so its verdict is the sign of det J inside, from the fillet's own report.
  const fillet::FilletQuality* fillet = nullptr;
  std::size_t fillet_cell = 0;  ///< its index among the fillet's cells (FilletQuality::cell_jacobian)
  /// A bridging fillet's half (Masalha et al. 2021, Sec. 6.1): singular on the edge by
  /// construction, judged the same way from its own report.
  const fillet::CornerQuality* corner = nullptr;
  geom::ValidityReport<3> validity;
  double volume = 0.0;
  /// A Boolean's piece: "boundary" (slice::piece_measures, exact) or "sampled"
  /// (slice::trimmed_volume, where the boundary measures are refused); null otherwise.
  const char* volume_method = nullptr;
};

/// A Shepard fillet's encoding fit (fillet/shepard.hpp) for component k: its two cells, a then b;
/// null for parametric fillets.
nlohmann::ordered_json shepard_fit(const scene::FilletBuild& f, std::size_t k) {
  if (f.shepard.size() < 2 * (k + 1)) return nullptr;
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (std::size_t h = 0; h < 2; ++h) {
    const auto& s = f.shepard[2 * k + h];
    out.push_back({{"max_error", s.max_error}, {"rms_error", s.rms_error}, {"check_error", s.check_error},
                   {"samples", s.samples}, {"seconds", s.seconds}});
  }
  return out;
}

/// The scene's derived surfaces (G+Smo patches merged, offsets: construct/patches.hpp).
nlohmann::ordered_json scene_surfaces(const scene::SceneBuild& built) {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const auto& s : built.surfaces) {
    nlohmann::ordered_json o{{"name", s.name}, {"kind", s.kind}, {"orders", s.orders}, {"counts", s.counts}};
    if (s.kind == "gismo") o["max_gap"] = s.max_gap;
    if (s.kind == "offset")
      o.update({{"distance", s.distance}, {"max_error", s.offset.max_error}, {"refinements", s.offset.refinements},
                {"samples", s.offset.samples}});
    o["seconds"] = s.seconds;
    out.push_back(std::move(o));
  }
  return out;
}

/// The constructor operations (Massarwi & Elber 2016, Sec. 3.2.2;
/// construct/tube_solid.hpp for tubes).
nlohmann::ordered_json constructs(const scene::SceneBuild& built) {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const auto& c : built.constructs) {
    nlohmann::ordered_json field = nullptr;
    if (c.has_field)
      field = {{"exact", c.field.exact}, {"max_error", c.field.max_error}, {"refinements", c.field.refinements},
               {"converged", c.field.converged}};
    out.push_back({{"name", c.name}, {"op", c.op}, {"cells", c.cells}, {"field", field}, {"seconds", c.seconds}});
  }
  return out;
}

nlohmann::ordered_json report(const scene::SceneBuild& built, const std::vector<CellQuality>& q, const Options& opt) {
  const auto& cells = built.model.cells;
  std::vector<std::string> source(cells.size());
  for (const auto& p : built.primitives)
    for (int i = 0; i < p.cell_count; ++i) source[static_cast<std::size_t>(p.first_cell + i)] = p.name;
  nlohmann::ordered_json jc = nlohmann::ordered_json::array();
  bool valid = true;
  double total = 0.0;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const auto& r = q[i].validity;
    if (q[i].fillet || q[i].corner) {
      const auto& det = q[i].fillet ? q[i].fillet->cell_jacobian.at(q[i].fillet_cell)
                                    : q[i].corner->cell_jacobian.at(q[i].fillet_cell);
      const bool ok = det[0] > 0.0;
      valid = valid && ok;
      total += q[i].volume;
      jc.push_back({{"name", cells[i].name},
                    {"primitive", nullptr},
                    {"orders", cells[i].volume.orders()},
                    {"counts", cells[i].volume.counts()},
                    {"valid", ok},
                    {"verdict", ok ? "fillet" : "invalid"},
                    {"min_jacobian", det[0]},
                    {"max_jacobian", det[1]},
                    {"volume", q[i].volume}});
      continue;
    }
    const bool ok = r.verdict == geom::Validity::valid || r.verdict == geom::Validity::degenerate;
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
    if (q[i].volume_method) jc.back()["volume_method"] = q[i].volume_method;
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
  nlohmann::ordered_json jf = nlohmann::ordered_json::array();
  for (const auto& f : built.fillets)
    for (std::size_t k = 0; k < f.quality.size(); ++k) {
      const auto& q2 = f.quality[k];
      const auto shape = [](const fillet::SplineShape& s) {
        return nlohmann::ordered_json{{"orders", s.orders}, {"counts", s.counts}};
      };
      nlohmann::ordered_json vbs = nullptr;
      if (q2.construction == fillet::Construction::vbs)
        vbs = {{"v_b", q2.vbs.v_b},           {"v_1", q2.vbs.v_1},
               {"v_2", q2.vbs.v_2},           {"c_gap", q2.vbs.c_gap},
               {"rail_gap", q2.vbs.rail_gap}, {"c_property_jump", q2.vbs.property_jump},
               {"reversed", q2.vbs.reversed}};
      nlohmann::ordered_json vrep = nullptr;
      if (q2.construction == fillet::Construction::vrep)
        vrep = {{"v_b", q2.vrep.v_b},
                {"c_gap", q2.vrep.c_gap},
                {"rail_gap", q2.vrep.rail_gap},
                {"c_property_jump", q2.vrep.property_jump},
                {"closed", q2.vrep.closed},
                {"cap_gap", q2.vrep.cap_gap},
                {"outside", q2.vrep.outside},
                {"hbs_volume", q2.vrep.hbs_volume},
                {"beyond_volume", q2.vrep.beyond_volume},
                {"beyond_jacobian", q2.vrep.beyond_jacobian},
                {"reversed", q2.vrep.reversed}};
      nlohmann::ordered_json shapes = nlohmann::ordered_json::array();
      for (const auto& s : q2.cells) shapes.push_back(shape(s));
      jf.push_back({{"name", f.name},
                    {"component", k + 1},
                    {"construction", fillet::construction_name(q2.construction)},
                    {"cells", f.cell_names[k]},
                    {"between", {{{"cell", f.cells[0]}, {"face", spline::face_name(f.faces[0])}},
                                 {{"cell", f.cells[1]}, {"face", spline::face_name(f.faces[1])}}}},
                    {"gap", q2.gap},
                    {"blend_gap", q2.blend_gap},
                    {"g1_angle", q2.g1_angle},
                    {"jacobian", q2.jacobian()},
                    {"min_jacobian", q2.det_min},
                    {"max_jacobian", q2.det_max},
                    {"cell_jacobian", q2.cell_jacobian},
                    {"glue", q2.glue},
                    {"property_jump", q2.property_jump},
                    {"composed", q2.composed},
                    {"rail_error", q2.rail_error},
                    {"sub1", shape(q2.sub[0])},
                    {"sub2", shape(q2.sub[1])},
                    {"blend", shape(q2.blend)},
                    {"fillet", shape(q2.fillet)},
                    {"cell_shapes", shapes},
                    {"vbs", vbs},
                    {"vrep", vrep},
                    {"seconds", q2.seconds},
                    {"shepard", shepard_fit(f, k)}});
    }
  nlohmann::ordered_json jb = nlohmann::ordered_json::array();
  for (const auto& b : built.bridges)
    jb.push_back({{"name", b.name},
                  {"cell", b.cell_name},
                  {"between", {{{"cell", b.cells[0]}, {"face", spline::face_name(b.faces[0])}},
                               {{"cell", b.cells[1]}, {"face", spline::face_name(b.faces[1])}}}},
                  {"orientation", b.quality.orientation},
                  {"g1_angle", b.quality.g1_angle},
                  {"min_jacobian", b.quality.det_min},
                  {"max_jacobian", b.quality.det_max},
                  {"seconds", b.seconds}});
  // Fillets over several faces (Masalha et al. 2021, Sec. 6.1): the bridging
  // fillets at convex corners.
  nlohmann::ordered_json jk = nlohmann::ordered_json::array();
  for (const auto& c : built.corners) {
    const auto& q2 = c.quality;
    const auto& jn = c.junction;
    jk.push_back({{"name", c.name},
                  {"cells", c.cell_names},
                  {"pieces", c.pieces},
                  {"gap_face", c.faces[0]},
                  {"edge_face", c.faces[1]},
                  {"o", jn.o},
                  {"p", jn.p},
                  {"q", jn.q},
                  {"r", jn.r},
                  {"angle", jn.angle},
                  {"end_error", q2.end_error},
                  {"radius_error", q2.radius_error},
                  {"o_error", q2.o_error},
                  {"r_error", q2.r_error},
                  {"g1_angle", q2.g1_angle},
                  {"glue", q2.glue},
                  {"glue_before", q2.glue_before},
                  {"property_jump", q2.property_jump},
                  {"property_jump_before", q2.property_jump_before},
                  {"jacobian", q2.jacobian()},
                  {"min_jacobian", q2.det_min},
                  {"max_jacobian", q2.det_max},
                  {"cell_volume", q2.cell_volume},
                  {"samples", q2.bd_samples},
                  {"seconds", q2.seconds},
                  {"part", c.part}});
    if (c.part >= 0)
      jk.back()["seam"] = {{"point", q2.seam_point},
                           {"gap", q2.seam_gap},
                           {"angle", q2.seam_angle},
                           {"glue", q2.seam_glue},
                           {"glue_before", q2.seam_glue_before},
                           {"property_jump", q2.seam_property_jump}};
  }
  // Concave corners (Masalha et al. 2021, Sec. 6): the pieces clipped at the
  // rails' crossing and stitched.
  nlohmann::ordered_json js = nlohmann::ordered_json::array();
  for (const auto& st : built.stitches) {
    const auto& jn = st.junction;
    js.push_back({{"name", st.name},
                  {"pieces", st.pieces},
                  {"crossing_face", st.faces[0]},
                  {"edge_face", st.faces[1]},
                  {"o", jn.o},
                  {"x", jn.x},
                  {"r", jn.r},
                  {"angle", jn.angle},
                  {"crossing", jn.crossing},
                  {"glue", jn.glue},
                  {"glue_before", jn.glue_before}});
  }
  return {{"scene", opt.scene},
          {"model", opt.output},
          {"units", built.model.units},
          {"properties", built.model.properties},
          {"valid", valid},
          {"volume", total},
          {"cells", jc},
          {"primitives", jp},
          {"fillets", jf},
          {"bridges", jb},
          {"corners", jk},
          {"stitches", js},
          {"surfaces", scene_surfaces(built)},
          {"constructs", constructs(built)}};
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
  if (!j["fillets"].empty()) {
    const auto cell_list = [](const nlohmann::ordered_json& f) {
      std::string cells;
      for (const auto& c : f["cells"]) cells += (cells.empty() ? "" : ",") + c.get<std::string>();
      return cells;
    };
    int width = 12;
    for (const auto& f : j["fillets"]) width = std::max(width, static_cast<int>(cell_list(f).size()));
    std::printf("\n%-14s %-*s %-22s %-6s %11s %11s %11s %11s %-13s %-9s %8s\n", "fillet", width, "cells", "between",
                "type", "gap", "glue", "G1 (rad)", "prop. jump", "det J", "S^ method", "seconds");
    for (const auto& f : j["fillets"]) {
      const auto& b = f["between"];
      const std::string between = b[0]["cell"].get<std::string>() + "." + b[0]["face"].get<std::string>() + "/" +
                                  b[1]["cell"].get<std::string>() + "." + b[1]["face"].get<std::string>();
      const auto mx = [&](const char* key) { return std::max(f[key][0].get<double>(), f[key][1].get<double>()); };
      const bool c0 = f["composed"][0].get<bool>(), c1 = f["composed"][1].get<bool>();
      std::printf("%-14s %-*s %-22s %-6s %11s %11s %11s %11s %-13s %-9s %8s\n",
                  (f["name"].get<std::string>() + "." + std::to_string(f["component"].get<int>())).c_str(), width,
                  cell_list(f).c_str(), between.c_str(), f["construction"].get<std::string>().c_str(),
                  fmt(std::max(mx("gap"), f["blend_gap"].get<double>()), 3).c_str(), fmt(f["glue"].get<double>(), 3).c_str(),
                  fmt(mx("g1_angle"), 3).c_str(), fmt(mx("property_jump"), 3).c_str(),
                  f["jacobian"].get<std::string>().c_str(), c0 && c1 ? "composed" : (c0 || c1 ? "mixed" : "fitted"),
                  fmt(f["seconds"].get<double>(), 3).c_str());
    }
    // V-rep fillets (Masalha et al. 2021, Alg. 6): the trimmed cell is T_hbs
    // less the solid beyond S_b.
    for (const auto& f : j["fillets"]) {
      if (f["vrep"].is_null()) continue;
      const auto& v = f["vrep"];
      std::printf("%s.%d (vrep): T_hbs %s - beyond S_b %s - %s = %s; S_b outside T_hbs by %s; %s\n",
                  f["name"].get<std::string>().c_str(), f["component"].get<int>(),
                  fmt(v["hbs_volume"].get<double>(), 8).c_str(), fmt(v["beyond_volume"][0].get<double>(), 8).c_str(),
                  fmt(v["beyond_volume"][1].get<double>(), 8).c_str(),
                  fmt(v["hbs_volume"].get<double>() - v["beyond_volume"][0].get<double>() -
                          v["beyond_volume"][1].get<double>(), 10).c_str(),
                  fmt(v["outside"].get<double>(), 3).c_str(),
                  v["closed"].get<bool>() ? "closed C, no caps"
                                          : ("caps within " + fmt(v["cap_gap"].get<double>(), 3) + " of S_b's ends").c_str());
    }
  }
  if (!j["bridges"].empty()) {
    std::printf("\n%-14s %-26s %-22s %11s %8s\n", "bridge", "between", "B matched", "G1 (rad)", "seconds");
    for (const auto& b : j["bridges"]) {
      const auto& bt = b["between"];
      const std::string between = bt[0]["cell"].get<std::string>() + "." + bt[0]["face"].get<std::string>() + "/" +
                                  bt[1]["cell"].get<std::string>() + "." + bt[1]["face"].get<std::string>();
      std::printf("%-14s %-26s %-22s %11s %8s\n", b["cell"].get<std::string>().c_str(), between.c_str(),
                  b["orientation"].get<std::string>().c_str(),
                  fmt(std::max(b["g1_angle"][0].get<double>(), b["g1_angle"][1].get<double>()), 3).c_str(),
                  fmt(b["seconds"].get<double>(), 3).c_str());
    }
  }
  if (!j["stitches"].empty()) {
    std::printf("\n%-14s %-30s %-30s %11s %11s\n", "stitch", "o", "rails cross at", "pinned", "glue");
    for (const auto& c : j["stitches"]) {
      const auto pt = [](const nlohmann::ordered_json& p) {
        return "(" + fmt(p[0].get<double>(), 6) + ", " + fmt(p[1].get<double>(), 6) + ", " + fmt(p[2].get<double>(), 6) + ")";
      };
      std::printf("%-14s %-30s %-30s %11s %11s\n", c["name"].get<std::string>().c_str(), pt(c["o"]).c_str(),
                  pt(c["x"]).c_str(), fmt(c["glue_before"].get<double>(), 3).c_str(), fmt(c["glue"].get<double>(), 3).c_str());
    }
  }
  if (!j["corners"].empty()) {
    std::printf("\n%-14s %-30s %11s %11s %11s %11s %-13s %12s %8s\n", "corner", "o", "rail error", "pinned", "glue",
                "G1 (rad)", "det J", "volume", "seconds");
    for (const auto& c : j["corners"]) {
      const auto& o = c["o"];
      const std::string at = "(" + fmt(o[0].get<double>(), 6) + ", " + fmt(o[1].get<double>(), 6) + ", " +
                             fmt(o[2].get<double>(), 6) + ")";
      const double rail = std::max({c["end_error"].get<double>(), c["radius_error"].get<double>(),
                                    c["o_error"].get<double>(), c["r_error"].get<double>()});
      std::printf("%-14s %-30s %11s %11s %11s %11s %-13s %12s %8s\n",
                  c["cells"][0].get<std::string>().substr(0, c["cells"][0].get<std::string>().size() - 1).c_str(),
                  at.c_str(), fmt(rail, 3).c_str(),
                  fmt(std::max(c["glue_before"][0].get<double>(), c["glue_before"][1].get<double>()), 3).c_str(),
                  fmt(std::max(c["glue"][0].get<double>(), c["glue"][1].get<double>()), 3).c_str(),
                  fmt(c["g1_angle"].get<double>(), 3).c_str(), c["jacobian"].get<std::string>().c_str(),
                  fmt(c["cell_volume"][0].get<double>() + c["cell_volume"][1].get<double>(), 8).c_str(),
                  fmt(c["seconds"].get<double>(), 3).c_str());
    }
  }
  if (!j["surfaces"].empty()) {
    std::printf("\n%-14s %-7s %-9s %-10s %s\n", "surface", "kind", "orders", "counts", "accuracy");
    for (const auto& s : j["surfaces"]) {
      const std::string orders = std::to_string(s["orders"][0].get<int>()) + "," + std::to_string(s["orders"][1].get<int>());
      const std::string counts = std::to_string(s["counts"][0].get<int>()) + "x" + std::to_string(s["counts"][1].get<int>());
      const std::string acc = s["kind"] == "gismo"
                                  ? "patch edges within " + fmt(s["max_gap"].get<double>(), 3)
                                  : "offset " + fmt(s["distance"].get<double>(), 6) + ": within " +
                                        fmt(s["max_error"].get<double>(), 3) + " of S + d n after " +
                                        std::to_string(s["refinements"].get<int>()) + " refinements";
      std::printf("%-14s %-7s %-9s %-10s %s\n", s["name"].get<std::string>().c_str(), s["kind"].get<std::string>().c_str(),
                  orders.c_str(), counts.c_str(), acc.c_str());
    }
  }
  if (!j["constructs"].empty()) {
    std::printf("\n%-14s %-17s %6s  %s\n", "construct", "op", "cells", "field");
    for (const auto& c : j["constructs"]) {
      std::string field = "(the surfaces' own)";
      if (!c["field"].is_null())
        field = c["field"]["exact"].get<bool>() ? "exact"
                                                : "max error " + fmt(c["field"]["max_error"].get<double>(), 3) +
                                                      " of the range after " +
                                                      std::to_string(c["field"]["refinements"].get<int>()) + " refinements";
      std::printf("%-14s %-17s %6zu  %s\n", c["name"].get<std::string>().c_str(), c["op"].get<std::string>().c_str(),
                  c["cells"].size(), field.c_str());
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
    const scene::Scene scene = scene::load_scene(opt->scene);
    const scene::SceneBuild built = scene::build_scene(scene);
    // Each cell's geometry: a primitive's before its field refined it (the same map).
    std::vector<const spline::Trivariate*> geometry;
    for (const auto& c : built.model.cells) geometry.push_back(&c.volume);
    for (const auto& p : built.primitives)
      for (int i = 0; i < p.cell_count; ++i)
        geometry[static_cast<std::size_t>(p.first_cell + i)] = &p.geometry[static_cast<std::size_t>(i)];
    std::vector<CellQuality> q(geometry.size());
    for (const auto& f : built.fillets)
      for (std::size_t k = 0; k < f.cell_names.size(); ++k)
        for (const auto& name : f.cell_names[k])
          for (std::size_t i = 0; i < built.model.cells.size(); ++i)
            if (built.model.cells[i].name == name) {
              q[i].fillet = &f.quality[k];
              q[i].fillet_cell = static_cast<std::size_t>(&name - f.cell_names[k].data());
            }
    for (const auto& c : built.corners)
      for (std::size_t h = 0; h < 2; ++h)
        for (std::size_t i = 0; i < built.model.cells.size(); ++i)
          if (built.model.cells[i].name == c.cell_names[h]) {
            q[i].corner = &c.quality;
            q[i].fillet_cell = h;
          }
    tbb::parallel_for(std::size_t{0}, geometry.size(), [&](std::size_t i) {
      // A fillet cell's volume comes with its report (the same integral over its faces: the
      // VBS cells' thousand-by-hundred elements made geom::volume take seconds).
      if (q[i].fillet) {
        q[i].volume = q[i].fillet->cell_volume.at(q[i].fillet_cell);
        return;
      }
      if (q[i].corner) {
        q[i].volume = q[i].corner->cell_volume.at(q[i].fillet_cell);
        return;
      }
      q[i].volume = geom::volume(*geometry[i]);
      // Rational trivariate cells have no Bezier-bound verdict (geom/validity.hpp): reported
      // as unchecked, not as invalid.
      q[i].checked = !geometry[i]->rational();
      if (q[i].checked) q[i].validity = geom::check_validity(*geometry[i]);
    });
    // Pieces of Booleans: the volume of the part their trimming admits (slice/trim.hpp).
    bool trimmed = false;
    for (std::size_t i = 0; i < built.model.cells.size(); ++i)
      trimmed = trimmed || (!built.model.cells[i].plain() && !q[i].fillet);
    if (trimmed) {
      // Exact from the piece's boundary faces (slice/piece_measures.hpp) where they close,
      // else sampled. A V-rep fillet's volume is exact from its report (T_hbs less the solid
      // beyond S_b).
      auto piece = [&](std::size_t i) { return !built.model.cells[i].plain() && !q[i].fillet; };
      bool sample = false;
      tbb::parallel_for(std::size_t{0}, geometry.size(), [&](std::size_t i) {
        if (!piece(i)) return;
        try {
          q[i].volume = slice::piece_measures(built.model, static_cast<int>(i)).volume;
          q[i].volume_method = "boundary";
        } catch (const std::exception&) {
          q[i].volume_method = "sampled";
        }
      });
      for (std::size_t i = 0; i < geometry.size(); ++i) sample = sample || (piece(i) && q[i].volume_method[0] == 's');
      if (sample) {
        const slice::Locator loc(built.model, {.tolerance = 1e-9 * slice::model_diagonal(built.model)});
        tbb::parallel_for(std::size_t{0}, geometry.size(), [&](std::size_t i) {
          if (piece(i) && q[i].volume_method[0] == 's') q[i].volume = slice::trimmed_volume(loc, static_cast<int>(i));
        });
      }
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
