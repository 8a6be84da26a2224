#include "vdb_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>

#include "trivox/error.hpp"
#include "trivox/io/sha256.hpp"

namespace trivox::io::detail {

namespace fs = std::filesystem;

namespace {

/// Where OpenVDB writes its random UUID: after the magic (8 bytes), the file format (4), the
/// library major and minor (4 + 4) and the grid offsets flag (1), as 36 characters
/// (Archive::writeHeader).
constexpr std::size_t uuid_offset = 21, uuid_size = 36;

constexpr char zero_uuid[] = "00000000-0000-0000-0000-000000000000";

bool looks_like_uuid(std::string_view u) {
  if (u.size() != uuid_size) return false;
  for (std::size_t i = 0; i < uuid_size; ++i) {
    const bool dash = i == 8 || i == 13 || i == 18 || i == 23;
    if (dash ? u[i] != '-' : !std::isxdigit(static_cast<unsigned char>(u[i]))) return false;
  }
  return true;
}

/// The first 128 bits of a SHA-256 digest (hex) as an RFC 9562 version 8 (custom) UUID.
std::string uuid_from_digest(const std::string& h) {
  std::string u;
  for (int i = 0; i < 16; ++i) {
    int byte = std::stoi(h.substr(static_cast<std::size_t>(2 * i), 2), nullptr, 16);
    if (i == 6) byte = (byte & 0x0f) | 0x80;
    if (i == 8) byte = (byte & 0x3f) | 0x80;
    char buf[3];
    std::snprintf(buf, sizeof buf, "%02x", byte);
    u += buf;
    if (i == 3 || i == 5 || i == 7 || i == 9) u += '-';
  }
  return u;
}

std::string reason(int err) { return std::strerror(err); }

/// Removes a temporary file unless released.
struct TempFile {
  fs::path path;
  bool keep = false;
  ~TempFile() {
    std::error_code ec;
    if (!keep && !path.empty()) fs::remove(path, ec);
  }
};

}  // namespace

VdbFileWritten write_vdb_file(const fs::path& path, const std::function<void(std::ostream&)>& write_archive) {
  auto fail = [&](const std::string& what, int err) {
    throw Error(path.string() + ": " + what + " (" + reason(err) + "); expected a writable folder with room for the file");
  };
  TempFile tmp;
  for (int attempt = 0; attempt < 100 && tmp.path.empty(); ++attempt) {
    std::string base = ".";
    base += path.filename().string();
    base += ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(attempt);
    const fs::path name = path.parent_path() / base;
    const int fd = ::open(name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      ::close(fd);
      tmp.path = name;
    } else if (errno != EEXIST) {
      fail("cannot create a temporary file", errno);
    }
  }
  if (tmp.path.empty()) fail("cannot create a temporary file", EEXIST);
  {
    std::ofstream os(tmp.path, std::ios::binary | std::ios::trunc);
    if (!os) fail("cannot open the temporary file", errno);
    write_archive(os);
    os.flush();
    if (!os) fail("writing failed", errno);
  }
  // The UUID: zeroed, the file hashed, the derived UUID written in its place.
  auto put_uuid = [&](std::string_view u) {
    std::fstream f(tmp.path, std::ios::binary | std::ios::in | std::ios::out);
    f.seekp(static_cast<std::streamoff>(uuid_offset));
    f.write(u.data(), static_cast<std::streamsize>(u.size()));
    f.flush();
    if (!f) fail("cannot update the file header", errno);
  };
  {
    std::ifstream in(tmp.path, std::ios::binary);
    std::string head(uuid_offset + uuid_size, '\0');
    if (!in.read(head.data(), static_cast<std::streamsize>(head.size())) ||
        !looks_like_uuid(std::string_view(head).substr(uuid_offset)))
      throw Error(path.string() + ": OpenVDB wrote an unexpected header (no UUID at byte 21); expected the "
                  "OpenVDB 10 file layout", ErrorKind::failed);
  }
  put_uuid(std::string_view(zero_uuid, uuid_size));
  put_uuid(uuid_from_digest(sha256_file(tmp.path)));
  const std::string digest = sha256_file(tmp.path);
  const int fd = ::open(tmp.path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0 || ::fsync(fd) != 0) fail("cannot flush the file to disk", errno);
  ::close(fd);
  if (::rename(tmp.path.c_str(), path.c_str()) != 0) fail("cannot rename the temporary file into place", errno);
  tmp.keep = true;
  const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
  std::error_code ec;
  return {static_cast<std::int64_t>(fs::file_size(path, ec)), digest};
}

}  // namespace trivox::io::detail
