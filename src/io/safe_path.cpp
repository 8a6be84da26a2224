#include "trivox/io/safe_path.hpp"

#include <fcntl.h>
#include <openssl/evp.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <memory>
#include <system_error>
#include <vector>

#include "trivox/error.hpp"

namespace trivox::io {

namespace fs = std::filesystem;

bool plain_file_name(std::string_view name) {
  if (name.empty() || name.size() > 255 || name == "." || name == "..") return false;
  for (const char c : name)
    if (c == '/' || c == '\\' || c == '\0') return false;
  return true;
}

bool regular_file_no_link(const fs::path& path) {
  std::error_code ec;
  return fs::is_regular_file(fs::symlink_status(path, ec));
}

std::optional<std::string> sha256_regular_file(const fs::path& path) {
  // O_NONBLOCK: a FIFO under the name must not block the open; it is then refused as not regular.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
  if (fd < 0) return std::nullopt;  // missing, a link (ELOOP), unreadable: not a file to trust
  struct Close {
    int fd;
    ~Close() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) return std::nullopt;
  struct CtxFree {
    void operator()(EVP_MD_CTX* c) const noexcept { EVP_MD_CTX_free(c); }
  };
  std::unique_ptr<EVP_MD_CTX, CtxFree> ctx(EVP_MD_CTX_new());
  if (!ctx || EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr) != 1)
    throw Error("SHA-256: libcrypto could not set up a digest; expected a working OpenSSL", ErrorKind::failed);
  std::vector<char> block(std::size_t{1} << 20);
  while (true) {
    const ssize_t n = ::read(fd, block.data(), block.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0)
      throw Error(path.string() + ": cannot read: " + std::strerror(errno) + "; expected a readable file",
                  ErrorKind::failed);
    if (n == 0) break;
    if (EVP_DigestUpdate(ctx.get(), block.data(), static_cast<std::size_t>(n)) != 1)
      throw Error("SHA-256: libcrypto failed while hashing; expected a working OpenSSL", ErrorKind::failed);
  }
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int len = 0;
  if (EVP_DigestFinal_ex(ctx.get(), digest, &len) != 1)
    throw Error("SHA-256: libcrypto failed while hashing; expected a working OpenSSL", ErrorKind::failed);
  static constexpr char hex[] = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < len; ++i) {
    out += hex[digest[i] >> 4];
    out += hex[digest[i] & 15];
  }
  return out;
}

std::optional<std::string> read_regular_file(const fs::path& path, std::int64_t max_bytes) {
  const std::string name = path.string();
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
  if (fd < 0) {
    const int err = errno;
    if (err == ENOENT) return std::nullopt;
    std::error_code ec;
    if (fs::is_symlink(fs::symlink_status(path, ec)))
      throw Error(name + ": is a symbolic link; expected a regular file that trivox wrote (links are not followed)");
    throw Error(name + ": cannot open: " + std::strerror(err) + "; expected a readable file");
  }
  struct Close {
    int fd;
    ~Close() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
    throw Error(name + ": not a regular file; expected a regular file that trivox wrote");
  if (st.st_size > max_bytes)
    throw Error(name + ": file size: " + std::to_string(st.st_size) + " bytes; expected at most " +
                std::to_string(max_bytes) + " bytes");
  std::string bytes;
  bytes.reserve(static_cast<std::size_t>(st.st_size));
  char chunk[1 << 16];
  while (true) {
    const ssize_t n = ::read(fd, chunk, sizeof chunk);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw Error(name + ": cannot read: " + std::strerror(errno) + "; expected a readable file");
    if (n == 0) break;
    if (static_cast<std::int64_t>(bytes.size()) + n > max_bytes)
      throw Error(name + ": file size: more than " + std::to_string(max_bytes) + " bytes; expected at most " +
                  std::to_string(max_bytes) + " bytes");
    bytes.append(chunk, static_cast<std::size_t>(n));
  }
  return bytes;
}

std::optional<std::string> temporary_owner(std::string_view name) {
  if (name.size() < 2 || name[0] != '.') return std::nullopt;
  const auto at = name.rfind(".tmp-");
  if (at == std::string_view::npos || at < 2) return std::nullopt;
  // After ".tmp-": <pid digits>-[<hex>-]<attempt digits>.
  const std::string_view tail = name.substr(at + 5);
  std::vector<std::string_view> parts;
  for (std::size_t from = 0;;) {
    const auto dash = tail.find('-', from);
    parts.push_back(tail.substr(from, dash == std::string_view::npos ? std::string_view::npos : dash - from));
    if (dash == std::string_view::npos) break;
    from = dash + 1;
  }
  const auto all = [](std::string_view s, bool hex) {
    if (s.empty() || s.size() > 20) return false;
    for (const char c : s)
      if (!((c >= '0' && c <= '9') || (hex && c >= 'a' && c <= 'f'))) return false;
    return true;
  };
  if (parts.size() != 2 && parts.size() != 3) return std::nullopt;
  if (!all(parts.front(), false) || !all(parts.back(), false)) return std::nullopt;
  if (parts.size() == 3 && !all(parts[1], true)) return std::nullopt;
  return std::string(name.substr(1, at - 1));
}

int remove_stale_temporaries(const fs::path& dir, const std::function<bool(const std::string&)>& owned) {
  int removed = 0;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const auto owner = temporary_owner(name);
    if (!owner || !owned(*owner)) continue;
    std::error_code se;
    if (!it->is_regular_file(se) || it->is_symlink(se)) continue;
    if (!fs::remove(it->path(), se) && se)
      throw Error(it->path().string() + ": cannot remove this temporary file of an earlier run (" + se.message() +
                  "); expected a folder trivox may write");
    if (!se) ++removed;
  }
  return removed;
}

}  // namespace trivox::io
