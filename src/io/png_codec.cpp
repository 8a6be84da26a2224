// Loading the PNG module (png_codec.hpp): dlopen on first use, from a short list of folders.
#include "png_codec.hpp"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "trivox/error.hpp"

namespace trivox::io::detail {

namespace fs = std::filesystem;

namespace {

/// The module's file name, the folder it is installed in relative to the executable's, and the
/// folder CMake built it in (CMakeLists.txt, trivox_core's compile definitions).
#ifndef TRIVOX_PNG_MODULE_NAME
#define TRIVOX_PNG_MODULE_NAME "libtrivox_png.so"
#endif
#ifndef TRIVOX_PNG_MODULE_INSTALL_DIR
#define TRIVOX_PNG_MODULE_INSTALL_DIR "../lib/trivox"
#endif
#ifndef TRIVOX_PNG_MODULE_BUILD_DIR
#define TRIVOX_PNG_MODULE_BUILD_DIR ""
#endif

/// Where to look, in order, without repeats.
std::vector<fs::path> candidate_dirs() {
  std::vector<fs::path> dirs;
  if (const char* env = std::getenv("TRIVOX_PLUGIN_DIR"); env && *env) {
    dirs.emplace_back(env);  // an override: nothing else is tried
    return dirs;
  }
  const auto add = [&dirs](const fs::path& dir) {
    const fs::path normal = dir.lexically_normal();
    for (const fs::path& d : dirs)
      if (d == normal) return;
    dirs.push_back(normal);
  };
  std::error_code ec;
  const fs::path exe = fs::canonical("/proc/self/exe", ec);
  if (!ec) {
    add(exe.parent_path());                                  // the build folder's layout
    add(exe.parent_path() / TRIVOX_PNG_MODULE_INSTALL_DIR);  // the installed layout
  }
  if (const fs::path built = TRIVOX_PNG_MODULE_BUILD_DIR; !built.empty()) add(built);
  return dirs;
}

/// The codec, or the error text naming every path tried.
struct Loaded {
  const PngCodec* codec = nullptr;
  std::string error;
};

Loaded load() {
  std::string tried;
  for (const fs::path& dir : candidate_dirs()) {
    const std::string path = (dir / TRIVOX_PNG_MODULE_NAME).string();
    std::string why;
    if (void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL)) {
      dlerror();
      if (auto entry = reinterpret_cast<PngCodecEntry>(dlsym(handle, TRIVOX_PNG_CODEC_ENTRY))) {
        if (const PngCodec* codec = entry()) return {codec, {}};  // never dlclose'd: the codec lives in it
        why = TRIVOX_PNG_CODEC_ENTRY "() returned no codec";
      } else {
        const char* e = dlerror();
        why = e ? e : "no " TRIVOX_PNG_CODEC_ENTRY;
      }
      dlclose(handle);
    } else {
      const char* e = dlerror();
      why = e ? e : "dlopen failed";
    }
    // dlerror() usually starts with the path; say it once.
    if (why.starts_with(path + ": ")) why.erase(0, path.size() + 2);
    tried += (tried.empty() ? "" : "; ") + path + " (" + why + ")";
  }
  return {nullptr, "cannot load the PNG module " TRIVOX_PNG_MODULE_NAME ": tried " +
                       (tried.empty() ? std::string("no folder") : tried) +
                       "; expected it next to the trivox executable, in " TRIVOX_PNG_MODULE_INSTALL_DIR
                       " from the executable's folder, or in the folder TRIVOX_PLUGIN_DIR names"};
}

}  // namespace

const PngCodec& png_codec() {
  static const Loaded loaded = load();  // once, whichever thread comes first
  if (!loaded.codec) throw Error(loaded.error, ErrorKind::failed);
  return *loaded.codec;
}

}  // namespace trivox::io::detail
