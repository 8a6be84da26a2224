/// @file trivox/io/vdb_color.hpp
/// @brief The colour space of the VDB's `color` and `Cd` grids: decoding sRGB-encoded colour
/// components (palette RGB / 255, a model's r, g, b) to linear RGB, which renderers take grid
/// colours as (docs/vdb.md, "Colour space").
///
/// The decode is the sRGB transfer function of IEC 61966-2-1:1999, section 5.2:
///   c <= 0.04045: c / 12.92;  otherwise ((c + 0.055) / 1.055)^2.4.
/// The two pieces meet at the knee to within 3e-9 (the standard's rounded constants), and the
/// decode maps 0 to 0 and 1 to 1. Cost: one pow per component above the knee.
#pragma once
#include <cmath>

namespace trivox::io {

/// The linear value of an sRGB-encoded component c (meant for 0..1; below 0 the linear
/// piece continues, above 1 the power piece).
inline double srgb_to_linear(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

}  // namespace trivox::io
