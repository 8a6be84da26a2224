/// @file trivox/slice/material.hpp
/// @brief Palettes of printable materials, and the mapping from a voxel's model properties to
///        the fractions of those materials it should be printed with.
///
/// A palette lists the printer's materials, each with the RGBA colour that stands for it in the
/// slice images (GrabCAD Voxel Print assigns a physical material to each colour key). Void is not
/// a material: it is the transparent colour 0 0 0 0 and the index `void_material` (255).
///
/// The mapper turns one voxel's properties into a fraction per palette material, non-negative
/// and summing to 1 (docs/materials.md has the full rules and the maths):
/// - a property named exactly like a palette material is that material's fraction;
/// - properties `r`, `g`, `b` (all three, values 0..1) are a colour, converted to cyan, magenta,
///   yellow, black and white by subtractive mixing with maximal black (K = 1 - max(r, g, b));
/// - explicit fractions come first and the colour fills what they leave (1 - their sum); the
///   result is normalised; a voxel with nothing usable prints in the palette's default material;
/// - other properties (density, ...) are ignored.
///
/// Cost: parsing a palette is linear in the file; MaterialMapper::fractions is O(properties +
/// materials) per voxel with no allocation.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace trivox::slice {

/// Material index that marks a void voxel in dithered output (and in Palette::find: never).
inline constexpr std::uint8_t void_material = 255;
/// Most materials a palette may hold: indices 0..253 (255 is void, 254 stays unused).
inline constexpr int max_palette_materials = 254;

/// One printable material.
struct Material {
  std::string name;                  ///< e.g. "VeroCyan-V": the key used in ConfigFile.xml
  std::array<std::uint8_t, 4> rgba;  ///< its colour in the slice images; alpha > 0, unique

  bool operator==(const Material&) const = default;
};

/// Roles of the colour conversion (properties r, g, b): which materials act as the five
/// subtractive primaries, by name. Defaults: the Vero names of the default palette.
struct ColourMaterials {
  std::string cyan = "VeroCyan-V";
  std::string magenta = "VeroMagenta-V";
  std::string yellow = "VeroYellow-V";
  std::string black = "VeroBlack";
  std::string white = "VeroUltraWhite";

  bool operator==(const ColourMaterials&) const = default;
};

/// The materials a job may print with.
struct Palette {
  std::string name = "custom";     ///< for summaries; "vero" for the default palette
  std::vector<Material> materials;  ///< 1..254 materials, names and colours unique
  int default_material = 0;         ///< index printed where properties give no fraction
  ColourMaterials rgb_materials;    ///< materials of the r, g, b conversion (checked when used)

  /// Index of the material called exactly `name`, or -1 if absent.
  int find(std::string_view name) const;

  bool operator==(const Palette&) const = default;
};

/// The default palette "vero": VeroCyan-V 0 137 166, VeroMagenta-V 198 0 88, VeroYellow-V
/// 240 197 0, VeroBlack 26 26 29, VeroUltraWhite 255 255 255, UltraClear 137 137 137 (all alpha
/// 255), in that order; default material VeroUltraWhite.
Palette default_palette();

/// Parses a palette file's text (format in docs/materials.md):
/// `{"trivox_palette": 1, "name": "...", "materials": [{"name": "VeroCyan-V", "rgba": [0,137,166,255]},
/// ...], "default": "VeroUltraWhite", "rgb_materials": {"cyan": ..., "magenta": ..., "yellow": ...,
/// "black": ..., "white": ...}}` ("name", "default" and "rgb_materials" optional).
/// @param json_text  the file's content
/// @param source     the file name, first in every message
/// @throws trivox::Error (bad_input) "<source>: <JSON pointer>: found ...; expected ..." for
///         malformed JSON (with line and column), a missing or wrong version, an empty list or
///         more than 254 materials, a bad or duplicate name, an rgba that is not 3 or 4 integers
///         0..255, alpha 0, a colour used twice, an unknown default or colour material, an
///         unknown key
Palette parse_palette(std::string_view json_text, const std::string& source);

/// Reads and parses a palette file; messages name the file as `file.string()`.
/// @throws trivox::Error (bad_input) when the file cannot be read, and as parse_palette
Palette load_palette(const std::filesystem::path& file);

/// The palette as a palette file (parse_palette(palette_json(p), s) == p), two-space indented,
/// one material per line, ending with a newline. "rgb_materials" is written when it names
/// materials of the palette and left out when it holds the defaults that the palette lacks.
/// @throws trivox::Error when rgb_materials names a material the palette lacks and is not the default
std::string palette_json(const Palette& palette);

/// Maps a model's per-voxel properties to palette material fractions (see the file comment).
/// Immutable after construction: one mapper may serve any number of threads.
class MaterialMapper {
public:
  /// @param palette         the job's palette (copied where needed; need not outlive the mapper)
  /// @param property_names  the model's property names, in the order of a voxel's values
  /// @throws trivox::Error (bad_input) when the model has properties r, g and b but the palette
  ///         lacks one of the five colour materials (Palette::rgb_materials)
  MaterialMapper(const Palette& palette, const std::vector<std::string>& property_names);
  /// The same, its errors prefixed by `source` (the palette's file) unless that is empty.
  MaterialMapper(const Palette& palette, const std::vector<std::string>& property_names, const std::string& source);

  /// Palette size: the length of a fraction vector.
  int materials() const noexcept { return materials_; }
  /// Number of properties a voxel's value array holds.
  int properties() const noexcept { return properties_; }
  /// True when no property drives a material: every voxel gets the default material.
  bool constant() const noexcept { return explicit_.empty() && !rgb_; }
  /// True when only the colour r, g, b drives the materials (no property names a material):
  /// then a voxel's fractions are cmykw_fractions of its colour, placed at colour_materials().
  bool colour_only() const noexcept { return rgb_ && explicit_.empty(); }
  /// Indices of r, g and b among the properties (meaningful when colour_only()).
  std::array<int, 3> colour_properties() const noexcept { return rgb_props_; }
  /// Material indices of cyan, magenta, yellow, black and white (meaningful when colour_only()).
  std::array<int, 5> colour_materials() const noexcept { return cmykw_; }

  /// Fractions of one voxel.
  /// @param props  properties() values, in the model's property order (NaN counts as 0)
  /// @param out    materials() values written: each >= 0, summing to 1 (within rounding)
  void fractions(const float* props, float* out) const noexcept;

  /// fractions() for `count` voxels stored one after the other (props: count * properties(),
  /// out: count * materials()).
  void fractions(const float* props, std::size_t count, float* out) const noexcept;

  /// fractions() for the voxels with cell[v] >= 0 among `count` (the others' outputs are left as
  /// they are): the print job's batch form, with a fast path for colour-only models.
  void fractions(const float* props, const std::int32_t* cell, std::size_t count, float* out) const noexcept;

  /// One line for the job summary, e.g. "r,g,b -> VeroCyan-V/VeroMagenta-V/VeroYellow-V/
  /// VeroBlack/VeroUltraWhite (subtractive CMYK + white); UltraClear -> UltraClear; ignored:
  /// density; default VeroUltraWhite".
  std::string describe() const;

private:
  struct Explicit {
    int property;
    int material;
  };
  int materials_ = 0;
  int properties_ = 0;
  int default_ = 0;
  std::vector<Explicit> explicit_;   // properties that name a material
  bool rgb_ = false;
  std::array<int, 3> rgb_props_{};   // indices of r, g, b among the properties
  std::array<int, 5> cmykw_{};       // material indices of cyan, magenta, yellow, black, white
  std::string describe_;
};

/// The subtractive conversion of a colour to cyan, magenta, yellow, black and white fractions
/// (docs/materials.md): with m = max(r, g, b) after clamping to [0, 1], K = 1 - m,
/// C = m - r, M = m - g, Y = m - b, W = r + g + b - 2m; when W < 0 (colours such as pure red
/// that side-by-side mixing of these five cannot reach) W = 0 and C, M, Y, K are scaled to sum 1.
/// Exact for reachable colours: averaging the ideal primaries (0,1,1), (1,0,1), (1,1,0), (0,0,0)
/// and (1,1,1) with these weights gives back (r, g, b).
/// @return {C, M, Y, K, W}, each in [0, 1], summing to 1
std::array<float, 5> rgb_to_cmykw(float r, float g, float b) noexcept;

/// rgb_to_cmykw into f[0..4], inline for kernels that map and dither in one pass (LayerDitherer::
/// dither_paint): every caller gets the same floats, operation for operation.
[[gnu::always_inline]] inline void cmykw_fractions(float r, float g, float b, float* f) noexcept {
  // The clamp also turns NaN into 0.
  r = r > 0.0f ? (r < 1.0f ? r : 1.0f) : 0.0f;
  g = g > 0.0f ? (g < 1.0f ? g : 1.0f) : 0.0f;
  b = b > 0.0f ? (b < 1.0f ? b : 1.0f) : 0.0f;
  const float m = std::max(r, std::max(g, b));
  const float w = r + g + b - 2.0f * m;
  // W < 0: out of reach of side-by-side mixing; drop white and keep the proportions of the
  // rest, whose sum is 1 - W. Branch-free (s = 1 exactly when W >= 0), since a colour field
  // near the edge of the reachable colours would make a branch unpredictable.
  const float s = 1.0f / (1.0f - std::min(w, 0.0f));
  f[0] = (m - r) * s, f[1] = (m - g) * s, f[2] = (m - b) * s, f[3] = (1.0f - m) * s, f[4] = std::max(w, 0.0f);
}

}  // namespace trivox::slice
