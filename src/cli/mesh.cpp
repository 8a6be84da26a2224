// `trivox mesh MODEL -o FILE`: the boundary of a model as a closed triangle mesh with vertex
// colours (vmodel/boundary_mesh.hpp; for models with trimmed cells, the pieces of Booleans,
// slice/trimmed_mesh.hpp), written as STL, PLY, OBJ or 3MF (io/mesh_file.hpp).
// Exit 1 when the mesh is not a closed manifold (nothing is written then).
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include "common.hpp"
#include "trivox/error.hpp"
#include "trivox/io/mesh_file.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/slice/trimmed_mesh.hpp"
#include "trivox/vmodel/boundary_mesh.hpp"

namespace trivox::cli {

namespace {

struct Options {
  std::string model, output, format;
  std::optional<double> tolerance;
  bool cells = false;
};

/// The output must be a file name in an existing folder trivox may write to: checked before the
/// work, so a bad path costs nothing.
void check_output(const std::filesystem::path& out) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (out.empty()) throw Error("--output: empty; expected a file name");
  if (fs::is_directory(out, ec)) throw Error(out.string() + ": is a folder; expected a file name to write");
  const fs::path dir = out.parent_path().empty() ? fs::path(".") : out.parent_path();
  if (!fs::is_directory(dir, ec))
    throw Error(out.string() + ": folder " + dir.string() + " does not exist; expected an existing, writable folder");
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw Error(out.string() + ": folder " + dir.string() + " is not writable; expected an existing, writable folder");
  if (fs::exists(out, ec) && ::access(out.c_str(), W_OK) != 0 && !fs::is_symlink(out, ec))
    throw Error(out.string() + ": the file is not writable; expected a file trivox may replace");
}

}  // namespace

void add_mesh(CLI::App& app, Common& common) {
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "mesh", "The model's boundary as a closed, outward-oriented triangle mesh with vertex colours (STL, PLY, OBJ, 3MF)");
  sub->add_option("MODEL", opt->model, "Model file (.json, or G+Smo .xml); trimmed cells (Booleans) are meshed from their trimmed faces")->required();
  sub->add_option("-o,--output", opt->output, "Mesh file to write (.stl, .ply, .obj or .3mf; replaced if it exists)")
      ->required();
  sub->add_option("--tolerance", opt->tolerance,
                  "Chordal tolerance in model units, > 0 (default 1e-3 of the model's diagonal)");
  sub->add_flag("--cells", opt->cells, "Every cell's own boundary as its own shell, instead of the model's boundary");
  sub->add_option("--format", opt->format, "stl, ply, obj or 3mf (default: from the output's extension)");
  sub->add_flag("--json", common.json, "Print one JSON object instead of the summary");
  sub->callback([opt, &common] {
    io::MeshFormat format{};
    if (!opt->format.empty()) {
      const auto f = io::mesh_format_from_name(opt->format);
      if (!f) throw Error("--format " + opt->format + ": unknown format; expected stl, ply, obj or 3mf");
      format = *f;
    } else {
      format = io::mesh_format_from_path(opt->output);
    }
    if (opt->tolerance && !(std::isfinite(*opt->tolerance) && *opt->tolerance > 0.0))
      throw Error("--tolerance " + fmt(*opt->tolerance) + ": expected a finite length > 0 in model units");
    check_output(opt->output);
    const auto model = io::load_model(opt->model);
    if (model.cells.empty())
      throw Error(opt->model + ": no cells; expected a model with at least one cell (a scene: trivox build first)");
    vmodel::MeshOptions mo;
    if (opt->tolerance) mo.tolerance = *opt->tolerance;
    mo.per_cell = opt->cells;
    // Trimmed cells: their boundary is their trimmed faces, untrimmed into patches and welded.
    const bool trimmed = slice::has_trimmed_cells(model);
    vmodel::BoundaryMesh mesh;
    try {
      if (trimmed) {
        slice::TrimmedMeshOptions to;
        to.mesh = mo;
        mesh = slice::mesh_trimmed_boundary(model, to);
      } else {
        mesh = vmodel::mesh_boundary(model, mo);
      }
    } catch (const Error& e) {
      throw e.within(opt->model);
    }
    const auto edges = vmodel::edge_report(mesh);
    const double volume = vmodel::enclosed_volume(mesh), area = vmodel::surface_area(mesh);
    const int shells = vmodel::shell_count(mesh);
    const auto euler = vmodel::euler_characteristic(mesh);
    if (!edges.manifold())
      throw Error(opt->model + ": the boundary mesh is not a closed manifold: " + std::to_string(edges.boundary_edges) +
                      " boundary edges, " + std::to_string(edges.non_manifold_edges) + " non-manifold edges, " +
                      std::to_string(edges.degenerate_triangles) +
                      " degenerate triangles (" +
                      (trimmed ? std::string("trimmed faces that do not meet within the weld distance, or ") : std::string()) +
                      "cells that overlap, or meet along faces that do not coincide as a whole); "
                      "expected every edge shared by two triangles; --cells meshes each cell on its own; nothing written",
                  ErrorKind::failed);
    io::MeshWriteOptions wo;
    wo.units = model.units;
    wo.name = std::filesystem::path(opt->model).stem().string();
    io::write_mesh(opt->output, mesh, format, wo);
    const bool colour = vmodel::colour_properties(mesh.property_names).has_value();
    if (common.json) {
      print_json({{"file", opt->model},
                  {"output", opt->output},
                  {"format", io::mesh_format_name(format)},
                  {"units", model.units},
                  {"cells", opt->cells},
                  {"trimmed", trimmed},
                  {"tolerance", mesh.tolerance},
                  {"max_deviation", mesh.max_deviation},
                  {"faces", mesh.faces},
                  {"vertices", mesh.vertices.size()},
                  {"triangles", mesh.triangles.size()},
                  {"dropped_triangles", mesh.dropped_triangles},
                  {"volume", volume},
                  {"cell_volume", mesh.cell_volume},
                  {"area", area},
                  {"shells", shells},
                  {"manifold", edges.manifold()},
                  {"euler", euler},
                  {"colour", colour && format != io::MeshFormat::stl}});
      return;
    }
    std::printf("%s: %zu triangles, %zu vertices (%s, %s)\n", opt->output.c_str(), mesh.triangles.size(),
                mesh.vertices.size(), io::mesh_format_name(format),
                colour && format != io::MeshFormat::stl ? "vertex colours" : "no colour");
    std::printf("faces %d, tolerance %s %s, largest deviation measured %s\n", mesh.faces, fmt(mesh.tolerance, 6).c_str(),
                model.units.c_str(), fmt(mesh.max_deviation, 6).c_str());
    std::printf("volume %s (cells %s %s, difference %s), area %s\n", fmt(volume, 10).c_str(),
                trimmed ? "from their trimmed faces" : "by quadrature", fmt(mesh.cell_volume, 10).c_str(), fmt(volume - mesh.cell_volume, 4).c_str(), fmt(area, 10).c_str());
    std::printf("closed manifold: %d shell%s, Euler characteristic %lld\n", shells, shells == 1 ? "" : "s",
                static_cast<long long>(euler));
  });
}

}  // namespace trivox::cli
