/// @file src/io/png_codec.hpp
/// @brief (private to trivox_core: io, and the slice job) The PNG codec that the module
/// `trivox_png` (src/io/png_plugin/) provides, and png_codec(), which loads that module the first
/// time a PNG is encoded or decoded.
///
/// Why a module: Debian's OpenImageIO pulls in about 260 shared libraries (OpenCV, GDAL, DCMTK,
/// ...), and resolving their symbols cost every trivox command about 0.33 s at start, `trivox
/// --version` included. Only the module links OpenImageIO, so commands that write or read no PNG
/// never load it. The module holds the OpenImageIO calls and nothing else: it reports failures
/// as bools and OpenImageIO's error text, and trivox_core words the messages and throws
/// trivox::Error. Both sides are built by the same compiler against the same libstdc++, so the
/// interface passes std::string and std::unique_ptr; no trivox type crosses it.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace trivox::io::detail {

/// What the encoder writes besides the pixels (8-bit RGBA, unassociated alpha, no row filter).
struct PngEncodeSettings {
  int width = 0, height = 0;  ///< positive (checked by the caller)
  int level = 1;              ///< zlib level 0..9 (checked by the caller)
  bool phys = false;           ///< whether to write a pHYs chunk, with these pixels per metre
  float pixels_per_metre_x = 0, pixels_per_metre_y = 0;  ///< whole numbers (the caller rounds)
};

/// One PNG being written into memory: open, then the whole image or strips of rows in order,
/// then finish. A false return leaves the reason in error().
class PngEncoder {
public:
  virtual ~PngEncoder() = default;
  virtual bool open(const PngEncodeSettings& settings) = 0;
  /// All rows, top to bottom, width * height * 4 bytes.
  virtual bool image(const std::uint8_t* rgba) = 0;
  /// Rows [y0, y1), (y1 - y0) * width * 4 bytes.
  virtual bool rows(int y0, int y1, const std::uint8_t* rgba) = 0;
  /// Closes the file; `png` receives its bytes.
  virtual bool finish(std::string& png) = 0;
  /// The pending error text (possibly empty), which it clears.
  virtual std::string error() = 0;
};

/// What a PNG's header and pHYs say.
struct PngSpec {
  int width = 0, height = 0, channels = 0, bits = 0;
  std::string resolution_unit;  ///< OpenImageIO's ResolutionUnit ("m", "inch", ...), or empty
  float x_resolution = 0, y_resolution = 0;
};

/// One PNG being read from memory that the caller keeps alive and unchanged meanwhile. Rows come
/// in increasing order (a PNG decodes sequentially). A false return leaves the reason in error().
/// The destructor closes the file and drops any pending error.
class PngDecoder {
public:
  virtual ~PngDecoder() = default;
  virtual const PngSpec& spec() const = 0;
  /// Rows [y0, y1) as channels 0..channels-1, 8 bits each.
  virtual bool rows(int y0, int y1, int channels, std::uint8_t* out) = 0;
  /// The whole image as channels 0..channels-1, 8 bits each.
  virtual bool image(int channels, std::uint8_t* out) = 0;
  virtual std::string error() = 0;
};

/// The module's entry: makes encoders and decoders. Stateless; safe to use from any thread.
class PngCodec {
public:
  /// A PNG encoder, or nullptr with the reason in `error`.
  virtual std::unique_ptr<PngEncoder> encoder(std::string& error) const = 0;
  /// A decoder of `bytes[0, size)` (`name` only for the decoder's own messages), or nullptr with
  /// the reason (possibly empty) in `error`.
  virtual std::unique_ptr<PngDecoder> decoder(const char* bytes, std::size_t size, const std::string& name,
                                              std::string& error) const = 0;

protected:
  ~PngCodec() = default;  // a static of the module, never deleted through this interface
};

/// The module's one exported symbol: `extern "C" const PngCodec* trivox_png_codec_v1()`. The
/// version is in the name, so a module built against another interface fails at dlsym.
#define TRIVOX_PNG_CODEC_ENTRY "trivox_png_codec_v1"
using PngCodecEntry = const PngCodec* (*)();

/// The codec, loading the module on first use (thread-safe; later calls cost a load of a
/// pointer). The module `libtrivox_png.so` is looked for in `$TRIVOX_PLUGIN_DIR` alone when that
/// variable is set and not empty; otherwise in the folder of the running executable (the real
/// path of /proc/self/exe), then in the build folder where CMake put it (a path compiled in).
/// It is loaded with RTLD_NOW | RTLD_LOCAL and never unloaded.
/// Cost: the first call about 0.3 s (the dynamic loader resolving OpenImageIO's dependencies).
/// @throws trivox::Error (failed) naming every path tried and the loader's reason (dlerror) for
///         each, when no candidate loads or exports the entry; every call throws it again.
const PngCodec& png_codec();

}  // namespace trivox::io::detail
