/// @file trivox/io/png_image.hpp
/// @brief 8-bit RGBA PNG images in memory: encoding a slice (from RGBA or from material
/// indices and their colours) and decoding one back, through the PNG module.
///
/// Cost: encoding is one zlib pass over the pixels (see encode_png_rgba for the level); decoding
/// one pass, the whole image in memory.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace trivox::io {

/// PNG bytes of an 8-bit RGBA image, through OpenImageIO, in memory (Filesystem::IOVecOutput),
/// so the caller can checksum them and write them with write_file_atomically. OpenImageIO is
/// reached through the PNG module `libtrivox_png.so`, loaded by the first PNG call (docs/cli.md,
/// "The PNG module"); all PNG functions here throw trivox::Error (failed) when it cannot be.
///
/// Settings (fixed, so the same pixels always give the same bytes): zlib level 1, no PNG row
/// filter. Measured on a full-tray J750 slice (11575 x 4606, tools/bench/bench_png.cpp, one
/// thread): 0.38 s (560 MB/s of RGBA) for a void slice, 0.75 s for a dithered quarter; level 6
/// takes 3 to 5 times as long for files 4 to 5 times smaller on void (0.2 instead of 0.9 MB);
/// libpng's default adaptive filtering tries five filters per row and costs 3 to 5 times the
/// time for no gain on palette colours ("None" beats "Sub" and "Up" in time, and on dithered
/// regions in size). docs/slice-output.md has the table. Alpha is stored as given (unassociated): colours are never premultiplied or altered.
/// No text or time chunks: identical pixels give identical files.
/// @param rgba          width * height * 4 bytes, rows top to bottom, R G B A per pixel
/// @param width,height  image size in pixels (positive)
/// @param dpi_x,dpi_y   physical resolution, stored in pHYs as pixels per metre (rounded to the
///                      nearest integer, as PNG requires); 0 or less: no pHYs chunk
/// @param level         zlib level 0..9 (the default 1 is the one slices use; previews use 6)
/// @throws trivox::Error (bad_input) on a non-positive size or a level outside 0..9;
///         (failed) when OpenImageIO reports an error or the PNG module cannot be loaded
std::string encode_png_rgba(const std::uint8_t* rgba, int width, int height, double dpi_x, double dpi_y,
                            int level = 1);

/// encode_png_rgba of the image whose pixel j is colours[index[j]]: the same bytes, from one
/// byte per pixel (material indices, as the print job keeps a group's layers) painted a strip of
/// rows at a time into a buffer of about 128 KB. Painting costs little next to the encoding
/// (eight pixels per vector permute where the indices are 0..6 or 255, on AVX2).
/// @param index    width * height material indices, rows top to bottom
/// @param colours  RGBA of each index, 4 bytes each in memory order R G B A
/// Other parameters and errors as encode_png_rgba.
std::string encode_png_indexed(const std::uint8_t* index, int width, int height, const std::array<std::uint32_t, 256>& colours,
                               double dpi_x, double dpi_y, int level = 1);

/// An 8-bit RGBA image read back from a PNG.
struct RgbaImage {
  int width = 0, height = 0;
  double dpi_x = 0, dpi_y = 0;             ///< from pHYs (0 when the file has none)
  std::vector<std::uint8_t> pixels;        ///< width * height * 4, rows top to bottom
};

/// Decodes PNG bytes (OpenImageIO) to 8-bit RGBA without premultiplying; an RGB file gets
/// alpha 255. Cost: one decode, the whole image in memory.
/// @param source  a name for messages
/// @throws trivox::Error (bad_input) naming `source` for bytes that are not a complete PNG, or a
///         PNG with other than 3 or 4 channels; (failed) when the PNG module cannot be loaded
RgbaImage decode_png_rgba(std::string_view bytes, const std::string& source);

}  // namespace trivox::io
