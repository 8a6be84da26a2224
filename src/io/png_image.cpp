// PNG encoding and decoding in memory (png_image.hpp), through the PNG module that png_codec()
// loads; slices painted from material indices a strip at a time (AVX2 where available).
#include "trivox/io/png_image.hpp"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>

#include "png_codec.hpp"
#include "png_rows.hpp"
#include "trivox/error.hpp"

namespace trivox::io {

// ------------------------------------------------------------------------------------------------
// PNG

namespace {

/// A PNG encoder into memory with the slices' settings (encode_png_rgba's comment): the module's
/// encoder, its failures turned into trivox::Error.
class SlicePngWriter {
public:
  SlicePngWriter(int width, int height, double dpi_x, double dpi_y, int level) {
    if (width <= 0 || height <= 0)
      throw Error("PNG of " + std::to_string(width) + " x " + std::to_string(height) +
                  " pixels; expected a positive width and height");
    if (level < 0 || level > 9) throw Error("PNG zlib level " + std::to_string(level) + "; expected 0..9");
    detail::PngEncodeSettings settings;
    settings.width = width;
    settings.height = height;
    settings.level = level;
    if (dpi_x > 0 && dpi_y > 0) {
      // pHYs holds whole pixels per metre and OpenImageIO truncates: hand it the rounded value
      // (exact in a float below 2^24, i.e. any dpi up to 400000).
      settings.phys = true;
      settings.pixels_per_metre_x = static_cast<float>(std::round(dpi_x / 0.0254));
      settings.pixels_per_metre_y = static_cast<float>(std::round(dpi_y / 0.0254));
    }
    std::string why;
    out_ = detail::png_codec().encoder(why);
    if (!out_) throw Error("PNG encoder unavailable: " + why, ErrorKind::failed);
    if (!out_->open(settings)) fail();
  }
  /// The whole image, rows top to bottom.
  void image(const std::uint8_t* rgba) {
    if (!out_->image(rgba)) fail();
  }
  /// Rows [y0, y1), in order.
  void rows(int y0, int y1, const std::uint8_t* rgba) {
    if (!out_->rows(y0, y1, rgba)) fail();
  }
  std::string finish() {
    std::string png;
    if (!out_->finish(png)) fail();
    return png;
  }

private:
  [[noreturn]] void fail() {
    std::string why = out_->error();
    throw Error("PNG encoding failed: " + (why.empty() ? std::string("unknown error") : why), ErrorKind::failed);
  }
  std::unique_ptr<detail::PngEncoder> out_;
};

/// rgba[4 j ..] = colours[index[j]] for j < n.
void paint_scalar(const std::uint8_t* index, std::size_t n, const std::array<std::uint32_t, 256>& colours, std::uint8_t* rgba) {
  for (std::size_t j = 0; j < n; ++j) std::memcpy(rgba + 4 * j, &colours[index[j]], 4);
}

#if defined(__x86_64__)
/// paint_scalar eight pixels at a time where their indices are 0..6 or 255 (a palette of up to
/// seven materials, and void): one permute from a table of those eight colours.
[[gnu::target("avx2")]] void paint_avx2(const std::uint8_t* index, std::size_t n, const std::array<std::uint32_t, 256>& colours,
                                        std::uint8_t* rgba) {
  std::int32_t t[8];
  for (int k = 0; k < 7; ++k) t[k] = static_cast<std::int32_t>(colours[static_cast<std::size_t>(k)]);
  t[7] = static_cast<std::int32_t>(colours[255]);
  const __m256i table = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(t));
  const __m256i seven = _mm256_set1_epi32(7), ff = _mm256_set1_epi32(255);
  std::size_t j = 0;
  for (; j + 8 <= n; j += 8) {
    const __m256i b = _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(index + j)));
    const __m256i lane = _mm256_min_epu32(b, seven);
    // An index 7..254 (lane 7 but not void) takes the table of all 256.
    const __m256i other = _mm256_andnot_si256(_mm256_cmpeq_epi32(b, ff), _mm256_cmpeq_epi32(lane, seven));
    if (!_mm256_testz_si256(other, other)) {
      paint_scalar(index + j, 8, colours, rgba + 4 * j);
      continue;
    }
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(rgba + 4 * j), _mm256_permutevar8x32_epi32(table, lane));
  }
  paint_scalar(index + j, n - j, colours, rgba + 4 * j);
}
#endif

void paint(const std::uint8_t* index, std::size_t n, const std::array<std::uint32_t, 256>& colours, std::uint8_t* rgba) {
#if defined(__x86_64__)
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (avx2) return paint_avx2(index, n, colours, rgba);
#endif
  paint_scalar(index, n, colours, rgba);
}

}  // namespace

std::string encode_png_rgba(const std::uint8_t* rgba, int width, int height, double dpi_x, double dpi_y, int level) {
  SlicePngWriter enc(width, height, dpi_x, dpi_y, level);
  enc.image(rgba);
  return enc.finish();
}

std::string encode_png_indexed(const std::uint8_t* index, int width, int height, const std::array<std::uint32_t, 256>& colours,
                               double dpi_x, double dpi_y, int level) {
  SlicePngWriter enc(width, height, dpi_x, dpi_y, level);
  // Strips of rows painted into a buffer that stays in the L1/L2 cache while libpng reads it.
  const auto w = static_cast<std::size_t>(width);
  const int strip = std::max(1, static_cast<int>(32768 / w));
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(std::min(strip, height)) * w * 4);
  for (int y0 = 0; y0 < height; y0 += strip) {
    const int y1 = std::min(height, y0 + strip);
    paint(index + static_cast<std::size_t>(y0) * w, static_cast<std::size_t>(y1 - y0) * w, colours, rgba.data());
    enc.rows(y0, y1, rgba.data());
  }
  return enc.finish();
}

RgbaImage decode_png_rgba(std::string_view bytes, const std::string& source) {
  if (const std::string p = detail::png_structure_problem(bytes); !p.empty()) throw Error(source + ": " + p);
  std::string why;
  const auto in = detail::png_codec().decoder(bytes.data(), bytes.size(), "memory.png", why);
  if (!in) throw Error(source + ": not a readable PNG: " + why + "; expected a complete PNG file");
  const detail::PngSpec& spec = in->spec();
  if (spec.channels != 3 && spec.channels != 4)
    throw Error(source + ": " + std::to_string(spec.channels) + " channels; expected RGB or RGBA");
  RgbaImage img;
  img.width = spec.width;
  img.height = spec.height;
  const std::size_t n = static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height);
  std::vector<std::uint8_t> native(n * static_cast<std::size_t>(spec.channels));
  if (!in->image(spec.channels, native.data()))
    throw Error(source + ": cannot decode: " + in->error() + "; expected a complete PNG file");
  if (spec.channels == 4) {
    img.pixels = std::move(native);
  } else {
    img.pixels.resize(n * 4);
    for (std::size_t k = 0; k < n; ++k) {
      std::memcpy(&img.pixels[4 * k], &native[3 * k], 3);
      img.pixels[4 * k + 3] = 255;
    }
  }
  // OpenImageIO reports pHYs in the unit it names; convert to pixels per inch.
  const std::string& unit = spec.resolution_unit;
  const double xr = spec.x_resolution, yr = spec.y_resolution;
  const double to_inch = unit == "inch" || unit == "in" ? 1.0 : unit == "cm" ? 2.54 : unit == "m" || unit == "meter" ? 0.0254 : 0.0;
  img.dpi_x = xr * to_inch;
  img.dpi_y = yr * to_inch;
  return img;  // the decoder closes the file
}

}  // namespace trivox::io
