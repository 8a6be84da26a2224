/// @file trivox/job/merge.hpp
/// @brief `trivox merge DIR`: joins the shards of a print job into one stack, one VDB and one
/// manifest, after checking every part.
///
/// Checks: every shard K of N has a manifest part, marked complete, of the same job as the others
/// (trivox version, model SHA-256, options, grid, palette); together the parts cover every layer
/// exactly once; every layer's PNG and every listed file exist with the SHA-256 the part records.
/// Anything wrong is reported all at once, per shard, with the command that redoes it, so that
/// only the failed shards are rerun. Then: ConfigFile.xml (voxel counts summed over the parts),
/// the .gcvf when the job asked for one (with shard 0's Mesh.stl when it lists one,
/// job/archive_mesh.hpp), the merged VDB when the parts have VDB parts, and
/// manifest.json (complete, shard 0 of 1), each written atomically; the parts stay.
///
/// Cost: one SHA-256 pass over every file (parallel), plus the VDB merge (io::merge_vdb_parts,
/// io/vdb_merge.hpp: linear in the active voxels).
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "trivox/job/manifest.hpp"

namespace trivox::job {

struct MergeSummary {
  int shards = 0;                      ///< N
  int layers = 0;                      ///< layers in the merged stack
  std::vector<std::int64_t> material_voxels;  ///< per material, summed
  std::vector<std::string> materials;
  std::int64_t inversion_failures = 0;
  std::vector<ManifestFile> files;     ///< what merge wrote (config, mesh, zip, vdb)
  /// Set when the job asked for a .gcvf and shard 0 lists no mesh: the archive has none.
  std::string mesh_warning;
};

/// Merges the shards in `dir`.
/// @throws Error (bad_input) when the folder has no shard manifests, parts of different jobs or
///         shard counts, or missing / unfinished / corrupt shards (the message names each with
///         what to rerun); (failed) when writing fails
MergeSummary merge_job(const std::filesystem::path& dir);

}  // namespace trivox::job
