/// @file trivox/io/mesh_file.hpp
/// @brief Triangle meshes (vmodel/boundary_mesh.hpp) as binary STL, PLY, OBJ and 3MF files.
///
/// Every format stores the mesh's shared vertices once where it can (PLY, OBJ, 3MF index them;
/// STL repeats them per facet, with the same bits each time) and coordinates as 32-bit floats
/// (STL, PLY) or decimal text (OBJ, 3MF). Colours are the model's r, g, b properties
/// (vmodel::colour_properties), sRGB components in 0..1 as the model format defines them:
///
///  - STL: binary (80-byte header not starting with "solid", a little-endian uint32 count,
///    then per facet the unit normal, three vertices as little-endian floats and a zero uint16
///    attribute). No colour: the attribute-word colour conventions of the VisCAM/SolidView and
///    Materialise readers disagree with each other, so none is written.
///  - PLY: `format binary_little_endian 1.0`; `element vertex` with float x, y, z and, with
///    colour, uchar red, green, blue; `element face` with `list uchar int vertex_indices`.
///  - OBJ: `v x y z r g b` with r, g, b in 0..1 (the vertex-colour extension that MeshLab,
///    Blender and GrabCAD Print read), `f a b c` with 1-based indices; coordinates with 9
///    significant digits (float precision).
///  - 3MF: through lib3mf (core specification plus the materials extension): one mesh object
///    and one build item, the model's units, and with colour a colour group with every triangle
///    carrying its three vertices' colours (p1, p2, p3), the object's default colour that of
///    vertex 0. The object's, the build item's and the build's UUIDs are derived from the SHA-256
///    of the mesh (RFC 9562 version 8), so the same mesh gives the same bytes.
///
/// Every file is encoded in memory and written with write_file_atomically (model_file.hpp):
/// a temporary name in the same folder, then a rename. Cost: linear in the mesh; memory: the
/// encoded file.
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "trivox/vmodel/boundary_mesh.hpp"

namespace trivox::io {

enum class MeshFormat { stl, ply, obj, threemf };

/// "stl", "ply", "obj", "3mf".
const char* mesh_format_name(MeshFormat f) noexcept;

/// The format called `name` (one of the names above), or nothing.
std::optional<MeshFormat> mesh_format_from_name(std::string_view name) noexcept;

/// The format of `path` from its extension (.stl, .ply, .obj, .3mf; any case).
/// @throws trivox::Error (bad_input) naming the path for any other extension
MeshFormat mesh_format_from_path(const std::filesystem::path& path);

struct MeshWriteOptions {
  /// The model's units (vmodel::VModel::units): 3MF records micron, mm, cm, inch, foot or m;
  /// the other formats have no unit.
  std::string units = "mm";
  /// The name of the 3MF object and the comment of PLY and OBJ headers (one line; no control
  /// characters).
  std::string name = "trivox";
  /// Write colours when the mesh has r, g, b properties.
  bool colour = true;
};

/// The file's bytes.
/// @throws trivox::Error (bad_input) for units 3MF cannot record, more than 2^32 - 1 vertices or
///         triangles; (failed) when lib3mf reports an error
std::string encode_mesh(const vmodel::BoundaryMesh& mesh, MeshFormat format, const MeshWriteOptions& options = {});

/// Writes the mesh to `path` atomically (see the file comment).
/// @throws trivox::Error as encode_mesh and write_file_atomically, naming the path
void write_mesh(const std::filesystem::path& path, const vmodel::BoundaryMesh& mesh, MeshFormat format,
                const MeshWriteOptions& options = {});

}  // namespace trivox::io
