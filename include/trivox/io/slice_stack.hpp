/// @file trivox/io/slice_stack.hpp
/// @brief Voxel Print slice stacks: PNG slices, `ConfigFile.xml`, the `.gcvf` zip, and reading a
/// stack back (inspection, a preview picture).
///
/// A stack is a folder holding `ConfigFile.xml` and one 8-bit RGBA PNG per layer, named
/// `<ImageFilePrefix><zero-padded index>.png` (docs/slice-output.md is the full reference). Every
/// pixel is one material's palette colour, or void (alpha 0). Image column i is x, image row r
/// holds j = ny - 1 - r (slice/grid.hpp): a slice viewed top-down shows the layer from +z, +y up.
///
/// `ConfigFile.xml` follows the layout GrabCAD Voxel Print writes and reads (root `<GCVF>`,
/// `Version` 2, `Resolution`, `SliceDimensions`, `SliceRange`, `MaterialList`); the element names
/// and nesting come from public tools that produce files Voxel Print accepts (jackcrane/slice2vox
/// `buildGCVF.js`, read back by jackcrane/voxelprint-preview `parseGCVF.js`).
///
/// Every file is written under a temporary name in the target folder and renamed into place
/// (model_file.hpp `write_file_atomically`): a reader never finds a partial file under a final
/// name, even if trivox is killed mid-write.
///
/// Cost: encoding is one zlib pass over the pixels (see encode_png_rgba for the level);
/// inspection and previews decode the PNGs they read once, streaming rows: memory per thread is
/// the compressed file plus about 1 MB of rows, whatever the slice size.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace trivox::io {

/// One printable material of a stack: its name in Voxel Print and its key colour in the slices.
struct StackMaterial {
  std::string name;                      ///< e.g. "VeroCyan-V"
  std::array<std::uint8_t, 4> rgba{};    ///< key colour; alpha must not be 0 (that is void)
  std::int64_t voxel_count = 0;          ///< voxels of this material in the whole stack

  friend bool operator==(const StackMaterial&, const StackMaterial&) = default;
};

/// What `ConfigFile.xml` says about a stack.
struct StackConfig {
  int version = 2;                        ///< `Version`: 2 is what Voxel Print files carry
  double dpi_x = 600, dpi_y = 300;        ///< `XDpi`, `YDpi`: pixels per inch along x (columns), y (rows)
  double slice_thickness_nm = 27000;      ///< `SliceThicknessNanoMeter`: layer thickness
  int width = 0, height = 0;              ///< `SliceWidth`, `SliceHeight`: pixels per slice
  int start_index = 0, slices = 0;        ///< `StartIndex`, `NumberOfSlices`
  std::string prefix = "slice_";          ///< `ImageFilePrefix`
  /// Zero padding of the index in file names (not in the XML: inspect_stack and read_stack_config
  /// find it from the folder). 0 or less: no padding.
  int digits = 5;
  int bit_depth = 4;                      ///< `BitDepth`: written as Voxel Print files carry it
  int max_colors = 6;                     ///< `MaxNumberOfColors`: idem
  std::string data_semantics = "Materials";  ///< `DataSemantics`
  std::string creation_mode = "MODEL_ONLY";  ///< `CreationMode`
  std::array<std::uint8_t, 4> background{0, 0, 0, 0};  ///< `BackGroundMaterialRGBA`: the void colour
  std::vector<StackMaterial> materials;   ///< `MaterialList`, in file order

  /// File name of slice i (0-based position in the stack): prefix + (start_index + i) padded
  /// with zeros to `digits` + ".png". Indices wider than `digits` are written in full.
  std::string slice_name(int i) const;
  /// Size of one voxel in mm^3: 25.4/dpi_x * 25.4/dpi_y * thickness.
  double voxel_volume_mm3() const noexcept {
    return (25.4 / dpi_x) * (25.4 / dpi_y) * (slice_thickness_nm * 1e-6);
  }

  friend bool operator==(const StackConfig&, const StackConfig&) = default;
};

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

/// `ConfigFile.xml` text for `config` (UTF-8, 2-space indented; names are XML-escaped):
/// ```
/// <GCVF>
///   <Version/> <Resolution><XDpi/><YDpi/><SliceThicknessNanoMeter/></Resolution>
///   <SliceDimensions><SliceWidth/><SliceHeight/></SliceDimensions>
///   <SliceRange><StartIndex/><NumberOfSlices/></SliceRange>
///   <BitDepth/> <MaxNumberOfColors/> <DataSemantics/> <CreationMode/> <ImageFilePrefix/>
///   <MaterialList><BackGroundMaterialRGBA>0 0 0 0</BackGroundMaterialRGBA>
///     <Material><Name/><RGBA>r g b a</RGBA><VoxelCount/></Material>...</MaterialList>
/// </GCVF>
/// ```
/// Numbers are written in the shortest form that reads back to the same double.
std::string config_xml(const StackConfig& config);

/// Parses `ConfigFile.xml` text. Elements are found by name anywhere below the root (older and
/// flat layouts read too); `BitDepth`, `MaxNumberOfColors`, `DataSemantics`, `CreationMode` and
/// `BackGroundMaterialRGBA` are optional. `digits` is left at its default (the file does not say).
/// @param source  the file name, prefixed to every message
/// @throws trivox::Error (bad_input) "<source>: GCVF/Resolution/XDpi: "abc" is not a number;
///         expected a positive number of pixels per inch" and the like: malformed XML (with line
///         and column), a missing element, a value out of range, an RGBA that is not four
///         integers 0..255, a transparent or repeated material colour
StackConfig parse_config_xml(std::string_view text, const std::string& source);

/// Reads `dir/ConfigFile.xml` and finds the zero padding of the slice names in `dir` (the width
/// of the digits in the first slice file present; 0 when none is).
/// @throws trivox::Error (bad_input) when `dir` is not a folder, has no ConfigFile.xml, or the
///         file is malformed (see parse_config_xml)
StackConfig read_stack_config(const std::filesystem::path& dir);

/// Writes `dir/ConfigFile.xml` for `config` atomically.
void write_stack_config(const std::filesystem::path& dir, const StackConfig& config);

/// Packs a stack into a `.gcvf` file: a zip holding `ConfigFile.xml` then every slice the
/// configuration names, in order, at the root of the archive (libzip; ZIP64 when needed). PNG
/// slices are stored (they are already deflated), ConfigFile.xml deflated; every entry carries
/// the time 1980-01-01 00:00 so the same stack gives the same bytes. Written to a temporary name
/// next to `gcvf` and renamed after fsync. Cost: one read of every slice.
/// @throws trivox::Error (bad_input) for a folder without a valid ConfigFile.xml, a missing
///         slice, or an unwritable target; (failed) when libzip reports an error
void zip_stack(const std::filesystem::path& dir, const std::filesystem::path& gcvf);

/// Where `trivox slice --zip` (and `trivox merge` of such a job) packs the folder `dir`:
/// `DIR.gcvf` beside it (a trailing '/' of `dir` ignored).
std::filesystem::path gcvf_path(const std::filesystem::path& dir);

/// One missing or corrupt slice.
struct SliceProblem {
  int index = 0;        ///< the slice's number as in its file name (start_index + position)
  std::string file;     ///< its file name
  std::string reason;   ///< "missing", "truncated or unreadable PNG: ...", "1000 x 20 pixels; expected ...",
                        ///< "37 pixels of foreign colours, first (12, 3) = 255 0 0 255; expected ..."
};

/// What a stack holds (inspect_stack).
struct StackReport {
  StackConfig config;                           ///< from ConfigFile.xml, `digits` from the folder
  int present = 0;                              ///< slices whose file exists
  std::vector<int> missing, corrupt;            ///< slice numbers (as in file names), ascending
  std::vector<SliceProblem> problems;           ///< one per missing or corrupt slice, in order
  std::vector<int> extra;                       ///< `<prefix><n>.png` files outside the range
  std::vector<std::int64_t> voxels_per_material;  ///< counted in readable slices, config.materials order
  std::vector<double> volume_per_material_mm3;  ///< voxels * voxel_volume_mm3
  std::vector<int> count_mismatch;              ///< materials whose VoxelCount differs from the count
                                                ///< (checked only when no slice is missing or corrupt)
  std::int64_t voxels = 0;                      ///< material voxels in all readable slices
  std::int64_t void_voxels = 0;                 ///< void pixels (alpha 0 or the background colour)
  std::int64_t foreign_pixels = 0;              ///< pixels of no palette colour, in all slices
  double voxel_volume_mm3 = 0;                  ///< one voxel
  double volume_mm3 = 0;                        ///< all material voxels

  /// No missing or corrupt slice, and every VoxelCount matches the pixels (only then are the
  /// counts complete; a mismatch alone also makes the stack invalid).
  bool valid() const noexcept { return missing.empty() && corrupt.empty() && count_mismatch.empty(); }
};

/// Reads a stack back: the configuration, then every slice (OpenImageIO, rows streamed, slices
/// in parallel with TBB). A slice is corrupt when it cannot be decoded to the end (truncated,
/// not a PNG), has another size than SliceWidth x SliceHeight, is not 8-bit RGB(A), or holds a
/// pixel that is neither void (alpha 0, or the background colour) nor a material's colour.
/// Voxels are counted per material over readable slices (foreign pixels are not counted).
/// Cost: one decode of every slice; memory per thread: one compressed slice and about 1 MB of rows.
/// @throws trivox::Error (bad_input) only when the folder or its ConfigFile.xml is unusable
///         (read_stack_config); slice problems are reported, never thrown; (failed) when the
///         PNG module cannot be loaded
StackReport inspect_stack(const std::filesystem::path& dir);

/// What write_preview drew.
struct PreviewSummary {
  int width = 0, height = 0;      ///< of the picture
  int every = 0;                  ///< slice step of the contact sheet
  std::vector<int> shown;         ///< slice numbers on the contact sheet
  std::vector<int> unreadable;    ///< slices missing or corrupt, ascending: those on the sheet (crossed
                                  ///< out) and those the cross-section needed (red rows)
  int section_row = 0;            ///< image row of the slices the cross-section goes through
  int section_width = 0, section_height = 0;  ///< size of the cross-section in the picture
  int section_z_scale = 1;        ///< vertical exaggeration of the section (1: true proportions)
};

/// A picture of a stack for a person: a contact sheet of every `every`-th slice (labelled with
/// the slice number), then a vertical cross-section (XZ plane through the middle image row,
/// x to the right, the top layer at the top), both scaled so voxels keep their physical
/// proportions (a 600 x 300 dpi slice is drawn half as tall per pixel row as it is wide per
/// column); a section that would be under 48 pixels tall (a thin job on a wide tray) is stretched
/// along z by a whole factor, labelled "XZ Z n:1". Colours are box-filtered (a dithered region shows its mean colour) and composited
/// over a dark grey checkerboard, so void shows as the checkerboard; missing or corrupt slices
/// are crossed out in red. Written as an opaque RGBA PNG (zlib level 6), atomically.
/// Cost: one decode of each shown slice, plus decoding each slice the cross-section samples up
/// to the middle row (at most one per picture row of the section), in parallel.
/// @param every  slice step; 0 picks ceil(slices / 16) (about 16 thumbnails)
/// @param width  picture width in pixels (64..16384)
/// @throws trivox::Error (bad_input) for an unusable folder or ConfigFile.xml, `every` < 0,
///         `width` out of range, more than 1024 thumbnails, or a picture over 32768 pixels tall;
///         (failed) when the PNG module cannot be loaded
PreviewSummary write_preview(const std::filesystem::path& dir, const std::filesystem::path& png, int every = 0,
                             int width = 1600);

}  // namespace trivox::io
