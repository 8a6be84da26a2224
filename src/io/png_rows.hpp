/// @file src/io/png_rows.hpp
/// @brief (private to trivox_core: io, and the slice job) Streaming a slice PNG row by row as 8-bit
/// RGBA, and finding the slice files of a stack folder. The decoding is the PNG module's
/// (png_codec.hpp), behind the pimpl.
#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <string_view>

namespace trivox::io::detail {

/// Reads a PNG's rows in increasing order (a PNG decodes sequentially), a chunk of rows at a
/// time, as 8-bit RGBA without premultiplying (RGB files get alpha 255). The file is read into
/// memory and its chunk structure checked first (png_structure_problem), so a truncated or
/// damaged file is reported without libpng printing on stderr. Memory: the file plus about
/// 1 MB of rows.
class PngRowReader {
public:
  /// Opens `path`; on failure ok() is false and error() says why.
  /// @throws trivox::Error (failed) when the PNG module cannot be loaded (png_codec()), which is
  ///         tried only for a file whose chunk structure is intact
  explicit PngRowReader(const std::filesystem::path& path);
  ~PngRowReader();
  PngRowReader(const PngRowReader&) = delete;
  PngRowReader& operator=(const PngRowReader&) = delete;

  bool ok() const noexcept { return error_.empty(); }
  const std::string& error() const noexcept { return error_; }
  int width() const noexcept { return width_; }
  int height() const noexcept { return height_; }
  int channels() const noexcept { return channels_; }
  int bits() const noexcept { return bits_; }
  /// Whether the file is 8-bit with 3 or 4 channels (what a slice must be); when not, error()
  /// is left alone and the caller reports `format_problem()`.
  std::string format_problem() const;

  /// Row `y` (0 = top) as width() * 4 bytes, valid until the next call; `y` must not decrease.
  /// nullptr when decoding fails (error() then says why, e.g. a truncated file).
  const std::uint8_t* row(int y);

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string error_;
  int width_ = 0, height_ = 0, channels_ = 0, bits_ = 0;
};

/// Slice files in `dir` named `<prefix><digits>.png`, by their number. Where two names give the
/// same number (slice_1.png and slice_00001.png), the first in name order is kept.
std::map<long long, std::string> list_slices(const std::filesystem::path& dir, const std::string& prefix);

/// Why `bytes` is not a whole PNG (bad signature, a chunk cut short or failing its CRC, no
/// IEND), as "<what>; expected ..."; empty when the chunk structure is intact.
std::string png_structure_problem(std::string_view bytes);

/// "r g b a"
std::string rgba_text(const std::uint8_t* p);

}  // namespace trivox::io::detail
