/// @file trivox/io/safe_path.hpp
/// @brief Names that trivox reads from files and turns into paths, kept inside their folder.
///
/// A manifest (job/manifest.hpp) names the files of a job; a hostile or damaged one could name
/// `../elsewhere/victim.vdb`, `/etc/shadow`, or a symbolic link that leads out of the folder.
/// These helpers are the one place where such names meet the file system: a name is accepted
/// only when it is a plain file name (no separator, not `.` or `..`, no NUL), and a file is
/// read or trusted only when it is a regular file reached without following a symbolic link at
/// its last component (`O_NOFOLLOW`, `symlink_status`). The folder itself is the user's choice
/// and may be reached through links.
///
/// Temporary files: every atomic write (model_file.hpp `write_file_atomically`, the VDB and
/// .gcvf writers) creates `.<name>.tmp-<pid>-...` next to `<name>` and renames it into place; a
/// process killed in between leaves it behind. `remove_stale_temporaries` clears those of names
/// the caller owns.
///
/// Cost: a `stat` per check; a SHA-256 pass over a file that is hashed; one folder listing for
/// the temporaries.
#pragma once
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace trivox::io {

/// Whether `name` is a plain file name: not empty, at most 255 bytes, no '/' or '\\', no NUL,
/// and neither "." nor "..". Such a name joined to a folder stays in that folder.
bool plain_file_name(std::string_view name);

/// Whether `path` is a regular file itself (not a symbolic link to one, nor anything else).
/// Never throws; a missing file or an error is false.
bool regular_file_no_link(const std::filesystem::path& path);

/// The SHA-256 (64 lowercase hex digits) of the regular file `path`, opened with O_NOFOLLOW, so
/// that a symbolic link at the last component is refused rather than followed.
/// @return nothing when the file is missing, a symbolic link, or not a regular file
/// @throws Error (failed) when the file opens but reading it fails (a failing device)
std::optional<std::string> sha256_regular_file(const std::filesystem::path& path);

/// The content of `path` when it is a regular file of at most `max_bytes`, opened with
/// O_NOFOLLOW (a symbolic link at the last component is refused, not followed). Memory: the
/// file's size.
/// @return nothing when no file of that name exists
/// @throws Error (bad_input) "<path>: is a symbolic link; expected ..." (or not a regular file,
///         or larger than max_bytes, or unreadable)
std::optional<std::string> read_regular_file(const std::filesystem::path& path, std::int64_t max_bytes);

/// The temporary name's owner: `.<name>.tmp-<pid>-<hex>-<attempt>` (or `-<pid>-<attempt>`)
/// gives `<name>`; any other name gives nothing.
std::optional<std::string> temporary_owner(std::string_view file_name);

/// Removes, in `dir`, the regular files (not links, not folders) named as the temporaries of an
/// atomic write of a name for which `owned` is true; other files stay.
/// @return how many were removed
/// @throws Error (bad_input) naming a file that cannot be removed
int remove_stale_temporaries(const std::filesystem::path& dir, const std::function<bool(const std::string&)>& owned);

}  // namespace trivox::io
