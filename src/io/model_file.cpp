#include "trivox/io/model_file.hpp"

#include <cmath>
#include <cstdio>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <thread>

#include "trivox/error.hpp"
#include "trivox/io/gismo_xml.hpp"
#include "trivox/io/model_json.hpp"

namespace trivox::io {

namespace {

namespace fs = std::filesystem;

std::string system_reason(int err) { return std::strerror(err); }

/// An open file descriptor, closed on every path out (a failed write must not leak it).
class Fd {
public:
  explicit Fd(int fd) noexcept : fd_(fd) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  int get() const noexcept { return fd_; }
  /// Closes now, reporting the error close() may give (NFS reports write errors here).
  int close() noexcept {
    const int r = ::close(fd_);
    fd_ = -1;
    return r;
  }

private:
  int fd_;
};

/// A fresh name next to `path` for the temporary file. Unique per process, thread and instant;
/// O_EXCL catches the rest.
fs::path temporary_name(const fs::path& path, int attempt) {
  const auto tid = std::hash<std::thread::id>{}(std::this_thread::get_id());
  const auto now = std::chrono::steady_clock::now().time_since_epoch().count();
  std::ostringstream s;
  s << "." << path.filename().string() << ".tmp-" << ::getpid() << "-" << std::hex
    << (tid ^ static_cast<std::size_t>(now)) << "-" << attempt;
  return path.parent_path() / s.str();
}

/// Creates the temporary file (0666 minus umask, like any new file); returns its descriptor.
int create_temporary(const fs::path& path, fs::path& tmp) {
  for (int attempt = 0; attempt < 100; ++attempt) {
    tmp = temporary_name(path, attempt);
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0 || errno != EEXIST) return fd;
  }
  errno = EEXIST;
  return -1;
}

bool write_all(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    bytes.remove_prefix(static_cast<std::size_t>(n));
  }
  return true;
}

[[noreturn]] void write_failed(const fs::path& path, const fs::path& tmp, int err) {
  if (!tmp.empty()) ::unlink(tmp.c_str());
  const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw Error(path.string() + ": cannot write: folder " + dir.string() +
                " does not exist; expected an existing, writable folder");
  // A full disk or a failing device stops a valid job (exit 1); a path the user may not write
  // to is the user's to change (exit 2).
  const bool device = err == ENOSPC || err == EDQUOT || err == EIO || err == EFBIG;
  throw Error(path.string() + ": cannot write: " + system_reason(err) +
                  (device ? "; expected room on the disk (the job can be resumed with --resume once there is)"
                          : "; expected a writable path"),
              device ? ErrorKind::failed : ErrorKind::bad_input);
}

/// Makes the rename itself durable; failure here loses nothing already written, so it is ignored.
void sync_folder(const fs::path& path) {
  const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

ModelFormat detect_model_format(std::string_view text, const std::string& source) {
  std::size_t i = text.starts_with("\xEF\xBB\xBF") ? 3 : 0;  // UTF-8 byte-order mark
  while (i < text.size() &&
         (text[i] == ' ' || text[i] == '\t' || text[i] == '\n' || text[i] == '\r'))
    ++i;
  const std::string expected =
      "expected a trivox JSON model (starting with '{') or G+Smo XML "
      "(starting with '<')";
  if (i == text.size()) throw Error(source + ": the file is empty; " + expected);
  if (text[i] == '{') return ModelFormat::json;
  if (text[i] == '<') return ModelFormat::gismo_xml;
  const unsigned char c = static_cast<unsigned char>(text[i]);
  const std::string shown =
      c >= 0x20 && c < 0x7f ? std::string("'") + text[i] + "'" : "byte " + std::to_string(c);
  throw Error(source + ": the file starts with " + shown + "; " + expected);
}

namespace {

/// Coordinates beyond this magnitude (in model units: a million kilometres in mm) are refused:
/// volumes multiply three of them, and 1e300 cubed is no longer a number.
constexpr double max_coordinate = 1e12;

std::string format_magnitude(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

template <int P>
void check_magnitudes(const spline::TensorSpline<P>& s, const std::string& where, bool json) {
  const int dim = s.dim();
  for (int r = 0; r < s.size(); ++r)
    for (int h = 0; h < dim; ++h) {
      const double v = s.point(r)[static_cast<std::size_t>(h)];
      if (std::abs(v) > max_coordinate)
        throw Error(where + (json ? "/points/" + std::to_string(r) + "/" + std::to_string(h)
                                  : " control point " + std::to_string(r) + " coordinate " + std::to_string(h)) +
                    ": " + format_magnitude(v) + "; expected a magnitude of at most 1e12 model units");
    }
}

}  // namespace

vmodel::VModel read_model(std::string_view text, const std::string& source, const Limits& limits) {
  const ModelFormat format = detect_model_format(text, source);
  vmodel::VModel m = format == ModelFormat::json ? read_model_json(text, source, limits)
                                                 : read_gismo_xml(text, source, limits);
  const bool json = format == ModelFormat::json;
  for (std::size_t i = 0; i < m.cells.size(); ++i)
    check_magnitudes(m.cells[i].volume,
                     source + ": " + (json ? "/cells/" + std::to_string(i) + "/trivariate" : m.cells[i].name), json);
  for (std::size_t i = 0; i < m.surfaces.size(); ++i)
    check_magnitudes(m.surfaces[i].surface,
                     source + ": " + (json ? "/surfaces/" + std::to_string(i) + "/surface" : m.surfaces[i].name), json);
  return m;
}

std::string read_file(const fs::path& path, const Limits& limits) {
  const std::string name = path.string();
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!fs::exists(st))
    throw Error(name + ": no such file; expected an existing model file (.json or G+Smo .xml)");
  if (fs::is_directory(st))
    throw Error(name + ": is a folder; expected a model file (.json or G+Smo .xml)");
  Fd fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (fd.get() < 0) throw Error(name + ": cannot open: " + system_reason(errno) + "; expected a readable file");
  const auto too_big = [&](const std::string& size) {
    return Error(name + ": file size: " + size + "; expected at most " + std::to_string(limits.max_file_bytes) +
                 " bytes" + limit_hint("max_file_bytes"));
  };
  struct stat info {};
  std::string bytes;
  if (::fstat(fd.get(), &info) == 0 && S_ISREG(info.st_mode)) {
    if (info.st_size > limits.max_file_bytes) throw too_big(std::to_string(info.st_size) + " bytes");
    bytes.reserve(static_cast<std::size_t>(info.st_size));
  }
  char chunk[1 << 16];
  while (true) {
    const ssize_t n = ::read(fd.get(), chunk, sizeof chunk);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw Error(name + ": cannot read: " + system_reason(errno) + "; expected a readable file");
    if (n == 0) break;
    if (static_cast<std::int64_t>(bytes.size()) + n > limits.max_file_bytes)
      throw too_big("more than " + std::to_string(limits.max_file_bytes) + " bytes");
    bytes.append(chunk, static_cast<std::size_t>(n));
  }
  return bytes;
}

std::string read_file(const fs::path& path) {
  Limits unbounded;  // outputs read back (manifests, VDB parts): no input-size limit of their own
  unbounded.max_file_bytes = std::numeric_limits<std::int64_t>::max();
  return read_file(path, unbounded);
}

vmodel::VModel load_model(const fs::path& path, const Limits& limits) {
  const std::string text = read_file(path, limits);
  return read_model(text, path.string(), limits);
}

void sync_folder_contents(const fs::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) throw Error(dir.string() + ": cannot open the folder to sync it: " + system_reason(errno), ErrorKind::failed);
  const int rc = ::syncfs(fd);
  const int err = errno;
  ::close(fd);
  if (rc != 0) throw Error(dir.string() + ": writing the files to disk failed: " + system_reason(err), ErrorKind::failed);
}

void write_file_atomically(const fs::path& path, std::string_view bytes, Durability durability) {
  std::error_code ec;
  if (fs::is_directory(path, ec))
    throw Error(path.string() + ": is a folder; expected a file path to write");
  fs::path tmp;
  Fd fd(create_temporary(path, tmp));
  if (fd.get() < 0) write_failed(path, {}, errno);
  const bool sync = durability == Durability::synced;
  if (!write_all(fd.get(), bytes) || (sync && ::fsync(fd.get()) != 0)) write_failed(path, tmp, errno);
  if (fd.close() != 0) write_failed(path, tmp, errno);
  if (::rename(tmp.c_str(), path.c_str()) != 0) write_failed(path, tmp, errno);
  if (sync) sync_folder(path);
}

void append_synced(const fs::path& path, std::string_view bytes) {
  Fd fd(::open(path.c_str(), O_WRONLY | O_APPEND | O_NOFOLLOW | O_CLOEXEC));
  if (fd.get() < 0) {
    if (errno == ELOOP) throw Error(path.string() + ": is a symbolic link; expected the job's own journal");
    write_failed(path, {}, errno);
  }
  if (!write_all(fd.get(), bytes) || ::fdatasync(fd.get()) != 0) write_failed(path, {}, errno);
  if (fd.close() != 0) write_failed(path, {}, errno);
}

void save_model(const vmodel::VModel& model, const fs::path& path) {
  if (path.extension() == ".xml")
    throw Error(path.string() +
                ": an .xml name; expected a .json name (trivox writes models "
                "as JSON only)");
  std::string text;
  try {
    text = write_model_json(model);
  } catch (const Error& e) {
    throw e.within(path.string());
  }
  write_file_atomically(path, text);
}

}  // namespace trivox::io
