// The .gcvf archive (gcvf.hpp): a stack zipped with libzip, deterministic bytes.
#include "trivox/io/gcvf.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <zip.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <string>
#include <thread>

#include "png_rows.hpp"
#include "trivox/error.hpp"
#include "trivox/io/safe_path.hpp"
#include "trivox/io/stack_config.hpp"

namespace trivox::io {

namespace fs = std::filesystem;

// ------------------------------------------------------------------------------------------------
// .gcvf

namespace {

/// A zip being written under a temporary name; discarded (and the file removed) unless closed.
class ZipWriter {
public:
  ZipWriter(const fs::path& target, const fs::path& tmp) : target_(target), tmp_(tmp) {
    int err = 0;
    zip_ = zip_open(tmp.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &err);
    if (!zip_) {
      zip_error_t e;
      zip_error_init_with_code(&e, err);
      const std::string why = zip_error_strerror(&e);
      zip_error_fini(&e);
      throw Error(target.string() + ": cannot create: " + why + "; expected a writable path");
    }
  }
  ~ZipWriter() {
    if (zip_) zip_discard(zip_);
    std::error_code ec;
    if (!done_) fs::remove(tmp_, ec);
  }
  ZipWriter(const ZipWriter&) = delete;
  ZipWriter& operator=(const ZipWriter&) = delete;

  void add_file(const fs::path& file, const std::string& name, bool deflate, std::time_t mtime) {
    zip_source_t* s = zip_source_file(zip_, file.c_str(), 0, -1);
    if (!s) fail("cannot read " + file.string());
    const zip_int64_t idx = zip_file_add(zip_, name.c_str(), s, ZIP_FL_ENC_UTF_8);
    if (idx < 0) {
      zip_source_free(s);
      fail("cannot add " + name);
    }
    const auto i = static_cast<zip_uint64_t>(idx);
    if (zip_set_file_compression(zip_, i, deflate ? ZIP_CM_DEFLATE : ZIP_CM_STORE, 0) != 0 ||
        zip_file_set_mtime(zip_, i, mtime, 0) != 0 ||
        zip_file_set_external_attributes(zip_, i, 0, ZIP_OPSYS_UNIX, 0100644u << 16) != 0)
      fail("cannot set the attributes of " + name);
  }

  void close() {
    if (zip_close(zip_) != 0) fail("cannot write");
    zip_ = nullptr;
    // zip_close wrote and renamed its own temporary into tmp_; make it durable, then publish it.
    const int fd = ::open(tmp_.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0 || ::fsync(fd) != 0) {
      const int err = errno;
      if (fd >= 0) ::close(fd);
      throw Error(target_.string() + ": cannot write: " + std::strerror(err) + "; expected a writable path");
    }
    ::close(fd);
    if (::rename(tmp_.c_str(), target_.c_str()) != 0)
      throw Error(target_.string() + ": cannot write: " + std::strerror(errno) + "; expected a writable path");
    done_ = true;
    const fs::path folder = target_.parent_path().empty() ? fs::path(".") : target_.parent_path();
    if (const int dfd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC); dfd >= 0) {
      ::fsync(dfd);
      ::close(dfd);
    }
  }

private:
  [[noreturn]] void fail(const std::string& what) {
    const std::string why = zip_ ? zip_strerror(zip_) : "";
    const bool io = zip_ && zip_error_code_system(zip_get_error(zip_)) != 0;
    throw Error(target_.string() + ": " + what + ": " + why + (io ? "; expected a writable path" : ""),
                io ? ErrorKind::bad_input : ErrorKind::failed);
  }

  fs::path target_, tmp_;
  zip_t* zip_ = nullptr;
  bool done_ = false;
};

/// 1980-01-01 00:00 local time: libzip stores local DOS times, so this reads back as the DOS
/// epoch in every time zone, and archives of the same stack are byte-identical.
std::time_t dos_epoch() {
  std::tm t{};
  t.tm_year = 80;
  t.tm_mon = 0;
  t.tm_mday = 1;
  t.tm_hour = 12;  // noon first, to dodge a DST gap at midnight; then back to 00:00
  t.tm_isdst = -1;
  std::time_t noon = std::mktime(&t);
  return noon - 12 * 3600;
}

}  // namespace

fs::path gcvf_path(const fs::path& dir) {
  fs::path zip = dir;
  if (!zip.has_filename()) zip = zip.parent_path();
  zip += ".gcvf";
  return zip;
}

void zip_stack(const fs::path& dir, const fs::path& gcvf, const std::vector<std::string>& extra) {
  const StackConfig c = read_stack_config(dir);
  const auto files = detail::list_slices(dir, c.prefix);
  std::vector<std::string> names;
  names.reserve(static_cast<std::size_t>(c.slices));
  for (int i = 0; i < c.slices; ++i) {
    const auto it = files.find(static_cast<long long>(c.start_index) + i);
    if (it == files.end())
      throw Error((dir / c.slice_name(i)).string() + ": missing; expected all " + std::to_string(c.slices) +
                  " slices that ConfigFile.xml lists before packing a .gcvf");
    names.push_back(it->second);
  }
  for (const auto& name : extra) {
    if (!plain_file_name(name))
      throw Error(name + ": not a plain file name; expected a file of the folder " + dir.string() + " to pack");
    std::error_code e;
    if (!fs::is_regular_file(fs::symlink_status(dir / name, e)))
      throw Error((dir / name).string() + ": missing or not a regular file; expected it beside the slices before packing a .gcvf");
  }
  std::error_code ec;
  if (fs::is_directory(gcvf, ec)) throw Error(gcvf.string() + ": is a folder; expected a .gcvf file path to write");
  std::ostringstream tmp_name;
  tmp_name << "." << gcvf.filename().string() << ".tmp-" << ::getpid() << "-" << std::hex
           << (std::hash<std::thread::id>{}(std::this_thread::get_id()) ^
               static_cast<std::size_t>(std::chrono::steady_clock::now().time_since_epoch().count()));
  const fs::path tmp = gcvf.parent_path() / tmp_name.str();
  const std::time_t mtime = dos_epoch();
  ZipWriter zip(gcvf, tmp);
  zip.add_file(dir / "ConfigFile.xml", "ConfigFile.xml", true, mtime);
  for (const auto& name : names) zip.add_file(dir / name, name, false, mtime);
  for (const auto& name : extra) zip.add_file(dir / name, name, true, mtime);
  zip.close();
}

}  // namespace trivox::io
