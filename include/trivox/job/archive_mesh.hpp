/// @file trivox/job/archive_mesh.hpp
/// @brief The boundary mesh that a `.gcvf` carries beside its slices: `Mesh.stl`, binary STL.
///
/// The public Voxel Print archives (docs/slice-output.md) hold, besides `ConfigFile.xml` and the
/// slices, the model's surface as `Mesh.stl` at the root of the zip; `ConfigFile.xml` does not
/// name it. A `--zip` job writes it into the slice folder (so that the folder is what the archive
/// unpacks to, and `trivox merge` of a sharded job finds it: shard 0 writes it) and packs it after
/// the slices.
///
/// The mesh is the one `trivox mesh MODEL -o Mesh.stl` writes with its defaults: the model's
/// boundary (vmodel::mesh_boundary, or slice::mesh_trimmed_boundary for models with trimmed
/// cells) at the default chordal tolerance (1e-3 of the model's diagonal), in the model's
/// coordinates, which the slicer takes as millimetres (slice/grid.hpp): the STL lies where the
/// slices' voxels do. A model that cannot be meshed (a face covered in part by another cell,
/// trimmed faces that do not close, a tolerance needing more than the mesher's caps: docs/mesh.md)
/// gives no mesh and the reason, and the archive is written without it.
///
/// Cost: one tessellation of the model (deterministic, no threads: the same bytes for any thread
/// count) and one STL encoding in memory (50 bytes a triangle).
#pragma once
#include <cstdint>
#include <string>

#include "trivox/vmodel/vmodel.hpp"

namespace trivox::job {

/// The mesh's name in the slice folder and at the root of the `.gcvf`.
inline constexpr const char* archive_mesh_name = "Mesh.stl";

struct ArchiveMesh {
  std::string stl;            ///< the binary STL's bytes; empty when the model could not be meshed
  std::string problem;        ///< why not ("" when meshed)
  std::int64_t triangles = 0;
  double tolerance = 0.0;     ///< the chordal tolerance used, model units (mm)
  double volume = 0.0;        ///< enclosed by the mesh
};

/// Meshes `model` for the archive (see the file comment). Errors of the mesher (trivox::Error)
/// and a mesh that is not a closed manifold become `problem`; nothing else is caught.
/// @param name  the model's name, in the STL's 80-byte header
ArchiveMesh archive_mesh(const vmodel::VModel& model, const std::string& name);

}  // namespace trivox::job
