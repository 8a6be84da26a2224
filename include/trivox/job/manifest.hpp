/// @file trivox/job/manifest.hpp
/// @brief What a print job wrote, and from what: `DIR/manifest.json` (or one part per shard),
/// which makes every job verifiable, resumable and splittable across machines.
///
/// A manifest names the job (trivox version, the model file's SHA-256, every option that changes
/// the output, the grid) and lists, per finished layer, its file, SHA-256, voxels per material
/// and inversion failures, plus the job's other files (VDB, ConfigFile.xml, .gcvf) with their
/// SHA-256. docs/slice-output.md has the format. A running job writes it once at its start and
/// appends the layers it finishes to a journal beside it (`manifest.journal`, every few seconds,
/// always after the layers it lists are on disk), then rewrites it whole at the end, listing
/// every layer, and removes the journal; so after a kill the manifest and its journal list only
/// complete layers, and the cost of keeping them is linear in the layer count.
///
/// Shards: job K of N (`--shard K/N`, or a scheduler's array index) slices a contiguous range of
/// layers aligned on 8 layers (an OpenVDB leaf's depth) and writes `manifest.shard-K-of-N.json`;
/// `trivox merge` checks the parts and writes `manifest.json`.
///
/// Cost: writing is linear in the layers; parsing likewise.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "trivox/io/stack_config.hpp"

namespace trivox::job {

/// One finished layer.
struct ManifestLayer {
  int index = 0;                       ///< layer k (0 at the bottom)
  std::string file;                    ///< its PNG's name in the folder
  std::string sha256;                  ///< of the PNG's bytes
  std::vector<std::int64_t> voxels;    ///< per palette material (Manifest::materials order)
  std::int64_t failures = 0;           ///< inversion failures in the layer

  bool operator==(const ManifestLayer&) const = default;
};

/// Another file of the job (VDB, ConfigFile.xml, the .gcvf zip).
struct ManifestFile {
  std::string role;    ///< "vdb", "config", "zip", "mesh" (the archive's Mesh.stl, in the folder)
  std::string file;    ///< name relative to the folder (the zip: relative to the folder's parent)
  std::string sha256;

  bool operator==(const ManifestFile&) const = default;
};

/// Which part of a job this process does: shard `index` of `count` (0 <= index < count).
struct Shard {
  int index = 0;
  int count = 1;

  bool operator==(const Shard&) const = default;
  /// "manifest.json" for a whole job, "manifest.shard-K-of-N.json" for a shard.
  std::string manifest_name() const;
  /// Its journal: "manifest.journal", "manifest.shard-K-of-N.journal".
  std::string journal_name() const;
  /// A file name with ".shard-K-of-N" before the extension for a shard (model.vdb ->
  /// model.shard-1-of-3.vdb), unchanged for a whole job.
  std::string part_name(const std::string& name) const;
  /// The layers [first, end) of `layers` this shard slices: contiguous ranges of whole blocks of
  /// `align` layers (the last block may be short), split as evenly as blocks allow; a shard may
  /// get none when there are fewer blocks than shards.
  std::array<int, 2> range(int layers, int align = 8) const;
};

/// Parses "K/N" (0 <= K < N <= 100000).
/// @throws Error (bad_input) naming `option` and the text
Shard parse_shard(const std::string& text, const std::string& option = "--shard");

/// The shard from a scheduler's environment when no --shard was given: Slurm job arrays
/// (SLURM_ARRAY_TASK_ID - SLURM_ARRAY_TASK_MIN of SLURM_ARRAY_TASK_COUNT), or a Kubernetes
/// Indexed Job (JOB_COMPLETION_INDEX, with the count from `shard_count`, i.e. --shard-count).
/// @param getenv  lookup of an environment variable (null when unset); std::getenv by default
/// @return nothing when no scheduler variable is set
/// @throws Error (bad_input) naming the variable for malformed or inconsistent values, or
///         JOB_COMPLETION_INDEX without a shard count
std::optional<Shard> shard_from_environment(std::optional<int> shard_count,
                                            const char* (*getenv)(const char*) = nullptr);

/// A job's manifest (or one shard's part of it).
struct Manifest {
  std::string trivox;                  ///< version that wrote it
  std::string model_file;              ///< the model's file name (as given)
  std::string model_sha256;            ///< of the model file's bytes
  /// Every option that changes the outputs, as canonical strings (printer, dpi, layer, palette
  /// name and SHA-256, dither, png, vdb, ...). Two jobs with equal identity write equal files.
  std::map<std::string, std::string> options;
  std::array<int, 3> grid{};           ///< voxels along x, y and layers
  double dpi_x = 0.0, dpi_y = 0.0;     ///< the PNG stack's resolution
  double layer_mm = 0.0;               ///< and layer thickness
  std::vector<std::string> materials;  ///< palette material names, the order of voxel counts
  std::vector<std::array<std::uint8_t, 4>> colours;  ///< their RGBA keys, same order
  Shard shard;                         ///< which part this is ({0, 1}: the whole job)
  std::array<int, 2> layer_range{};    ///< [first, end) of the layers this part slices
  std::vector<ManifestLayer> layers;   ///< finished layers, ascending index
  std::vector<ManifestFile> files;     ///< other outputs, once complete
  bool complete = false;               ///< every layer of the range and every file is written

  /// Same trivox version, model, options, grid and materials: outputs may be shared.
  bool same_job(const Manifest& other) const;
  /// The first difference from `other`'s identity, e.g. "the model's SHA-256 differs", or "".
  std::string difference(const Manifest& other) const;
  /// The layer k, or null.
  const ManifestLayer* layer(int k) const;
};

/// A number as an option value: the shortest text that reads back to the same double (0.027,
/// not 0.027000000000000000).
std::string option_number(double v);

/// The ConfigFile.xml of the job's PNG stack: resolution, size and palette from the manifest,
/// with voxel counts `totals` (one per material).
io::StackConfig stack_config_of(const Manifest& manifest, const std::vector<std::int64_t>& totals);

/// The manifest as JSON text (2-space indented, keys in a fixed order, ending with a newline).
std::string manifest_json(const Manifest& manifest);

/// Parses a manifest. Every name that trivox turns into a path is checked to be the one trivox
/// writes, inside the folder (io/safe_path.hpp `plain_file_name`): a layer's file is
/// `slice_<k>.png` (zero-padded or not) for its index k; `files` roles are "config"
/// (`ConfigFile.xml`), "vdb" (`<model>.vdb`, a shard's `<model>.shard-K-of-N.vdb` of its own K
/// and N), "zip" (`../<folder>.gcvf`, whose folder name the reader compares with the folder it
/// read), "mesh" (`Mesh.stl`, job/archive_mesh.hpp), each at most once. A path with a separator, `..`, an absolute path or a NUL is refused.
/// @param source  the file name, for messages
/// @throws Error (bad_input) "<source>: <JSON pointer>: ...; expected ..." for anything malformed,
///         e.g. "m.json: /files/0/file: found the string \"../x\"; expected a file name inside
///         the folder"
Manifest parse_manifest(std::string_view text, const std::string& source);

/// The journal of a running job: the layers it finished since its manifest was written, one
/// JSON object per line (JSON Lines), appended every few seconds after the layers it lists are
/// on disk. Its first line binds it to the manifest it extends:
/// `{"trivox_journal":1,"manifest_sha256":"<SHA-256 of the manifest file's bytes>"}`, so a
/// journal left beside another manifest (a later job's, or the job's own compacted one) is never
/// read into it. Each further line is a layer as in the manifest's "layers".

/// The journal name of manifest `manifest_name` (".json" replaced by ".journal").
std::string journal_name_of(const std::string& manifest_name);

/// A new journal's first line for the manifest whose file bytes are `manifest_text`.
std::string journal_header(std::string_view manifest_text);

/// One finished layer as a journal line (compact JSON and a newline).
std::string journal_line(const ManifestLayer& layer);

/// Adds the layers of `journal_text` to `manifest` (parsed from `manifest_text`), keeping its
/// layers in ascending order (a journal's layer replaces the manifest's of the same index).
/// Nothing is added when the journal belongs to another manifest (its header's digest differs)
/// or the manifest is complete. A last line without its newline (a write cut short by a kill)
/// and every line from the first that does not read as a layer of this manifest onwards are
/// left out: the layers they name are simply redone by `--resume`.
/// @return the number of layers read from the journal
std::size_t apply_journal(Manifest& manifest, std::string_view manifest_text, std::string_view journal_text);

/// Reads `dir / name` when it exists; nothing when it does not. The file is opened without
/// following a symbolic link (io::read_regular_file) and may hold at most 256 MiB. An incomplete
/// manifest gets the layers of its journal (`journal_name_of(name)`, apply_journal) when that is
/// a regular file of at most 256 MiB; otherwise the journal is left out.
/// @throws Error (bad_input) when it exists but is a link or not a regular file, is too large,
///         cannot be read or does not parse
std::optional<Manifest> read_manifest(const std::filesystem::path& dir, const std::string& name);

/// The name of the job's whole VDB, derived from the model file's name: `<stem>.vdb`
/// (`model.vdb` for a name without a stem), as the VDB job names it; always a plain file name.
std::string vdb_file_name(const Manifest& manifest);

/// The `files` entry that a `--zip` job in folder `dir` records for its archive:
/// "../<folder name>.gcvf" (io::gcvf_path).
std::string zip_entry_name(const std::filesystem::path& dir);

}  // namespace trivox::job
