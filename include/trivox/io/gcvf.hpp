/// @file trivox/io/gcvf.hpp
/// @brief The `.gcvf` file: a Voxel Print slice stack packed into one zip archive.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace trivox::io {

/// Packs a stack into a `.gcvf` file: a zip holding `ConfigFile.xml`, every slice the
/// configuration names, in order, then the files `extra` names (the boundary mesh `Mesh.stl`,
/// job/archive_mesh.hpp), all at the root of the archive (libzip; ZIP64 when needed). PNG
/// slices are stored (they are already deflated), ConfigFile.xml and the extra files deflated;
/// every entry carries the time 1980-01-01 00:00 so the same stack gives the same bytes. Written
/// to a temporary name next to `gcvf` and renamed after fsync. Cost: one read of every file.
/// @param extra  plain file names in `dir` (no separator, not "." or ".."), packed in this order
/// @throws trivox::Error (bad_input) for a folder without a valid ConfigFile.xml, a missing
///         slice or extra file, an extra name that is not a plain name, or an unwritable target;
///         (failed) when libzip reports an error
void zip_stack(const std::filesystem::path& dir, const std::filesystem::path& gcvf,
               const std::vector<std::string>& extra = {});

/// Where `trivox slice --zip` (and `trivox merge` of such a job) packs the folder `dir`:
/// `DIR.gcvf` beside it (a trailing '/' of `dir` ignored).
std::filesystem::path gcvf_path(const std::filesystem::path& dir);

}  // namespace trivox::io
