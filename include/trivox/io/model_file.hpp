/// @file trivox/io/model_file.hpp
/// @brief Loading a model from disk in any supported format, and saving one safely.
///
/// `load_model` reads the whole file and picks the reader by content, not by extension: the
/// first character other than white space (and a UTF-8 byte-order mark) is `{` for a trivox JSON
/// model (model_json.hpp) or `<` for G+Smo XML (gismo_xml.hpp). `save_model` writes JSON to a
/// temporary file in the target's folder, flushes it to disk and renames it over the target, so
/// a reader never sees a partial file under the final name, even if trivox is killed mid-write.
///
/// Reading obeys the limits (trivox/limits.hpp): `load_model` refuses a file above max_file_bytes
/// from its size before reading a byte (and stops reading one that grows, or a device that never
/// ends, at the limit); the readers check the rest.
///
/// Cost: one read (or write) of the file plus the parse (or format), linear in its size.
#pragma once
#include <filesystem>
#include <string>
#include <string_view>

#include "trivox/limits.hpp"
#include "trivox/vmodel/vmodel.hpp"

namespace trivox::io {

enum class ModelFormat {
  json,       ///< trivox model file (model_json.hpp)
  gismo_xml,  ///< G+Smo XML geometry (gismo_xml.hpp)
};

/// Which reader `text` needs, from its first significant character.
/// @param source  the file name, for the message
/// @throws trivox::Error (bad_input) for an empty file or one starting with anything else
ModelFormat detect_model_format(std::string_view text, const std::string& source);

/// Parses `text` with the reader its content calls for, within `limits` (all but max_file_bytes).
/// @throws trivox::Error (bad_input) for every problem the readers report
vmodel::VModel read_model(std::string_view text, const std::string& source,
                          const Limits& limits = default_limits());

/// Reads and parses the model file at `path`; messages name the file as `path.string()`.
/// @param limits  the limits the file must keep; by default the process's (trivox/limits.hpp)
/// @throws trivox::Error (bad_input) when the file is missing, a directory, unreadable or larger
///         than limits.max_file_bytes, and for every problem the readers report
vmodel::VModel load_model(const std::filesystem::path& path, const Limits& limits = default_limits());

/// Writes `model` as a JSON model file at `path`, replacing any file there atomically.
/// @throws trivox::Error (bad_input) when `path` ends in `.xml` (trivox writes JSON only), when
///         the model cannot be written (see write_model_json) or the folder is not writable
void save_model(const vmodel::VModel& model, const std::filesystem::path& path);

/// The whole content of a file, as bytes, without a size limit: for files trivox wrote and reads
/// back (manifests, VDB parts); inputs from users go through the overload with Limits.
/// @throws trivox::Error (bad_input) "<path>: no such file; expected ..." and similar
std::string read_file(const std::filesystem::path& path);

/// The whole content of an input file (model, scene) of at most limits.max_file_bytes: a larger
/// regular file is refused from its size before a byte is read, and reading anything else (a
/// pipe, a device) stops one byte past the limit. Memory: the file's size, at most the limit.
/// @throws trivox::Error (bad_input) as read_file, and "<path>: file size: N bytes; expected at
///         most M bytes (limit max_file_bytes; raise it with --limit max_file_bytes=N)"
std::string read_file(const std::filesystem::path& path, const Limits& limits);

/// When a written file reaches the disk.
enum class Durability {
  synced,   ///< fsync of the file and its folder before returning
  deferred  ///< left to the system, or to a later sync_folder_contents (many files of one job)
};

/// Writes `bytes` to `path` through a temporary file in the same folder and a rename: the file
/// at `path` is either the old one or the complete new one. With Durability::synced (the
/// default) also after a crash of the machine; with deferred, only once the caller has called
/// sync_folder_contents (a job writes its layers deferred, syncs once, and then writes the file
/// that marks the job complete synced).
/// @throws trivox::Error (bad_input) naming the path and the system's reason
void write_file_atomically(const std::filesystem::path& path, std::string_view bytes,
                           Durability durability = Durability::synced);

/// Appends `bytes` to the existing regular file `path` (a journal) and syncs it (fdatasync)
/// before returning. The file is opened without following a symbolic link.
/// @throws trivox::Error naming the path: failed for a full disk or a failing device, bad_input
///         for a missing file, a link or a path the user may not write
void append_synced(const std::filesystem::path& path, std::string_view bytes);

/// Flushes every file written so far in the file system that holds `dir` (syncfs).
/// @throws trivox::Error (failed) naming the folder when the system reports a write error
void sync_folder_contents(const std::filesystem::path& dir);

}  // namespace trivox::io
