/// @file trivox/io/stack_config.hpp
/// @brief A Voxel Print slice stack's description, `ConfigFile.xml`: writing, parsing, reading
/// it from a stack folder, and the slice file names it implies.
///
/// A stack is a folder holding `ConfigFile.xml` and one 8-bit RGBA PNG per layer, named
/// `<ImageFilePrefix><index>.png`, the index unpadded as the public writers name them
/// (`slice_0.png`; zero padding on request) (docs/slice-output.md is the full reference). Every
/// pixel is one material's palette colour, or void: the background colour the file declares
/// (transparent `0 0 0 0` or opaque black `0 0 0 255`). Image column i is x, image row r
/// holds j = ny - 1 - r (slice/grid.hpp): a slice viewed top-down shows the layer from +z, +y up.
///
/// `ConfigFile.xml` follows the layout GrabCAD Voxel Print writes and reads (root `<GCVF>`,
/// `Version` 2, `Resolution`, `SliceDimensions`, `SliceRange`, `MaterialList`); the element names
/// and nesting come from public tools that produce files Voxel Print accepts (jackcrane/slice2vox
/// `buildGCVF.js`, read back by jackcrane/voxelprint-preview `parseGCVF.js`).
///
/// Every file is written under a temporary name in the target folder and renamed into place
/// (model_file.hpp `write_file_atomically`): a reader never finds a partial file under a final
/// name, even if trivox is killed mid-write. Cost: a few kilobytes of XML.
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
  /// `XDpi`, `YDpi`: pixels per inch along x (columns), y (rows). Whole numbers to be written
  /// (every reader parses them as integers); a file read may hold fractions.
  double dpi_x = 600, dpi_y = 300;
  double slice_thickness_nm = 27000;      ///< `SliceThicknessNanoMeter`: layer thickness; idem
  int width = 0, height = 0;              ///< `SliceWidth`, `SliceHeight`: pixels per slice
  int start_index = 0, slices = 0;        ///< `StartIndex`, `NumberOfSlices`
  std::string prefix = "slice_";          ///< `ImageFilePrefix`
  /// Zero padding of the index in file names (not in the XML: inspect_stack and read_stack_config
  /// find it from the folder). 0 or 1: none (`slice_7.png`), as the public writers name slices.
  int digits = 0;
  int bit_depth = 4;                      ///< `BitDepth`: written as Voxel Print files carry it
  /// `MaxNumberOfColors`: the materials the printer holds at once (slice::PrintProfile::channels);
  /// the `MaterialList` may not list more.
  int max_colors = 6;
  std::string data_semantics = "Materials";  ///< `DataSemantics`
  std::string creation_mode = "MODEL_ONLY";  ///< `CreationMode`
  /// `BackGroundMaterialRGBA`: the void colour, painted in every slice where there is no
  /// material (stack_background: transparent or black).
  std::array<std::uint8_t, 4> background{0, 0, 0, 0};
  /// `MaterialList`, in file order: the materials the stack uses (a voxel count above 0).
  std::vector<StackMaterial> materials;

  /// File name of slice i (0-based position in the stack): prefix + (start_index + i) padded
  /// with zeros to `digits` + ".png". Indices wider than `digits` are written in full.
  std::string slice_name(int i) const;
  /// Size of one voxel in mm^3: 25.4/dpi_x * 25.4/dpi_y * thickness.
  double voxel_volume_mm3() const noexcept {
    return (25.4 / dpi_x) * (25.4 / dpi_y) * (slice_thickness_nm * 1e-6);
  }

  friend bool operator==(const StackConfig&, const StackConfig&) = default;
};

/// The void colours a stack may declare, by name: "transparent" (`0 0 0 0`, as OpenVCAD's
/// exporter writes) and "black" (`0 0 0 255`, as slice2vox writes and voxelprint-preview reads).
/// @throws trivox::Error (bad_input) "--background NAME: unknown; expected transparent or black"
std::array<std::uint8_t, 4> stack_background(std::string_view name);
/// The name of a void colour stack_background knows ("transparent", "black"), else "r g b a".
std::string stack_background_name(const std::array<std::uint8_t, 4>& rgba);

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
/// Every number is written as an integer, as every reader parses them.
/// @throws trivox::Error (bad_input) for a config a reader would misread: a resolution or layer
///         thickness that is not a whole number (of dots per inch, of nanometres), more materials
///         than `max_colors` (listing them), a material coloured like the background, and the
///         ranges of parse_config_xml
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

}  // namespace trivox::io
