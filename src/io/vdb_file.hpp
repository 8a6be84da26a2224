/// @file src/io/vdb_file.hpp
/// @brief (private to src/io) Writing an OpenVDB file atomically and reproducibly: the bytes go
/// to a temporary name in the target's folder (`.<name>.tmp-<pid>-<n>`), the random UUID that
/// OpenVDB puts into every header is replaced in place by one derived from the SHA-256 of the
/// file with the UUID zeroed, then fsync and a rename over the target (and an fsync of the
/// folder). A reader never sees a partial file, and the same grids give the same bytes.
///
/// The OpenVDB calls stay with the callers (vdb_volume.cpp, vdb_merge.cpp): they stream the
/// archive into the stream given to them, so this file needs no OpenVDB header.
/// Cost: the caller's streaming, plus two SHA-256 passes over the file (about 1 s per GB) and
/// two 36-byte header updates; memory stays constant.
#pragma once
#include <filesystem>
#include <functional>
#include <ostream>

#include "trivox/io/vdb_volume.hpp"

namespace trivox::io::detail {

/// Writes the file `path` through a temporary file in its folder: `write_archive` streams an
/// OpenVDB archive (header first, as Archive::write does, seekable) into the given binary
/// stream, and throws trivox::Error (failed) when OpenVDB fails. Returns the size and SHA-256 of
/// the file written.
/// @throws Error (bad_input) when the temporary file cannot be created, written, flushed or
///         renamed (the message names `path` and the reason); (failed) when the stream does not
///         start with an OpenVDB 10 header (a UUID at byte 21), or from `write_archive`
VdbFileWritten write_vdb_file(const std::filesystem::path& path,
                              const std::function<void(std::ostream&)>& write_archive);

}  // namespace trivox::io::detail
