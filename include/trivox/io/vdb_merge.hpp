/// @file trivox/io/vdb_merge.hpp
/// @brief Joining the VDB parts that the shards of one print job wrote (disjoint slabs of whole
/// 8-layer leaves) into one file with the same grids, metadata and grid order: byte-identical
/// to the file an unsharded job writes (`trivox merge`).
///
/// The first part gives the grids, their file order (that of its grid descriptors) and the
/// file's metadata; every other part's grids, matched by name, must have the same type and
/// transform, and their leaves move into the first part's trees (`Cd`, an instance of `color`'s
/// tree, is merged once). OpenVDB's file statistics (file_bbox_*, file_voxel_count, ...) are
/// dropped so that the writer computes them afresh. The file is written like VdbVolume::write
/// (vdb_volume.hpp): a temporary name, the UUID derived from the content, fsync and a rename.
/// Cost: reading every part whole (the grids of all parts in memory at once), a merge linear in
/// the leaves, the write and two SHA-256 passes over the file.
#pragma once
#include <filesystem>
#include <vector>

namespace trivox::io {

/// Joins the VDB files `parts` (in shard order) into one file `out`.
/// @throws Error (bad_input) for no parts, an unreadable part, or parts whose grids differ
///         (names, types, transforms); (failed) when writing fails
void merge_vdb_parts(const std::vector<std::filesystem::path>& parts, const std::filesystem::path& out);

}  // namespace trivox::io
