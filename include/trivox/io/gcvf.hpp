/// @file trivox/io/gcvf.hpp
/// @brief The `.gcvf` file: a Voxel Print slice stack packed into one zip archive.
#pragma once
#include <filesystem>

namespace trivox::io {

/// Packs a stack into a `.gcvf` file: a zip holding `ConfigFile.xml` then every slice the
/// configuration names, in order, at the root of the archive (libzip; ZIP64 when needed). PNG
/// slices are stored (they are already deflated), ConfigFile.xml deflated; every entry carries
/// the time 1980-01-01 00:00 so the same stack gives the same bytes. Written to a temporary name
/// next to `gcvf` and renamed after fsync. Cost: one read of every slice.
/// @throws trivox::Error (bad_input) for a folder without a valid ConfigFile.xml, a missing
///         slice, or an unwritable target; (failed) when libzip reports an error
void zip_stack(const std::filesystem::path& dir, const std::filesystem::path& gcvf);

/// Where `trivox slice --zip` (and `trivox merge` of such a job) packs the folder `dir`:
/// `DIR.gcvf` beside it (a trailing '/' of `dir` ignored).
std::filesystem::path gcvf_path(const std::filesystem::path& dir);

}  // namespace trivox::io
