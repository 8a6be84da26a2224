// The boundary mesh of a .gcvf (archive_mesh.hpp).
#include "trivox/job/archive_mesh.hpp"

#include "trivox/error.hpp"
#include "trivox/io/mesh_file.hpp"
#include "trivox/slice/trimmed_mesh.hpp"
#include "trivox/vmodel/boundary_mesh.hpp"

namespace trivox::job {

ArchiveMesh archive_mesh(const vmodel::VModel& model, const std::string& name) {
  ArchiveMesh out;
  vmodel::BoundaryMesh mesh;
  try {
    mesh = slice::has_trimmed_cells(model) ? slice::mesh_trimmed_boundary(model) : vmodel::mesh_boundary(model);
  } catch (const Error& e) {
    out.problem = e.what();
    return out;
  }
  const auto edges = vmodel::edge_report(mesh);
  if (!edges.manifold()) {
    out.problem = "the boundary mesh is not a closed manifold: " + std::to_string(edges.boundary_edges) +
                  " boundary edges, " + std::to_string(edges.non_manifold_edges) + " non-manifold edges, " +
                  std::to_string(edges.degenerate_triangles) + " degenerate triangles";
    return out;
  }
  io::MeshWriteOptions wo;
  wo.name = name;
  wo.colour = false;
  out.stl = io::encode_mesh(mesh, io::MeshFormat::stl, wo);
  out.triangles = static_cast<std::int64_t>(mesh.triangles.size());
  out.tolerance = mesh.tolerance;
  out.volume = vmodel::enclosed_volume(mesh);
  return out;
}

}  // namespace trivox::job
