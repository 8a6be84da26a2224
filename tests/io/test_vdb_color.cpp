// The sRGB decode of the VDB's colour grids (io/vdb_color.hpp) against values of IEC 61966-2-1's
// transfer function computed independently to 40 digits (Python's decimal module:
// exp(2.4 ln((c + 0.055) / 1.055))).
#include <catch2/catch.hpp>

#include "trivox/io/vdb_color.hpp"

using trivox::io::srgb_to_linear;

TEST_CASE("srgb_to_linear: exact values of IEC 61966-2-1", "[vdb]") {
  CHECK(srgb_to_linear(0.0) == 0.0);
  CHECK_THAT(srgb_to_linear(1.0), Catch::WithinAbs(1.0, 1e-15));
  CHECK_THAT(srgb_to_linear(0.5), Catch::WithinAbs(0.2140411404822324424, 1e-15));
  CHECK_THAT(srgb_to_linear(128.0 / 255.0), Catch::WithinAbs(0.2158605001138991638, 1e-15));
  // The linear piece: 0.02 / 12.92; the knee itself is on it.
  CHECK_THAT(srgb_to_linear(0.02), Catch::WithinAbs(0.02 / 12.92, 1e-18));
  CHECK_THAT(srgb_to_linear(0.04045), Catch::WithinAbs(0.0031308049535603715, 1e-18));
}

TEST_CASE("srgb_to_linear: continuous at the knee and increasing", "[vdb]") {
  // Just above the knee, the power piece: its value at the knee is 0.0031308072830676825,
  // 2.3e-9 above the linear piece's (the standard's constants are rounded).
  const double above = srgb_to_linear(0.04045 + 1e-12);
  CHECK(above - srgb_to_linear(0.04045) > 0.0);
  CHECK(above - srgb_to_linear(0.04045) < 3e-9);
  double previous = -1.0;
  for (int i = 0; i <= 1000; ++i) {
    const double v = srgb_to_linear(i / 1000.0);
    CHECK(v > previous);
    CHECK(v <= i / 1000.0 + 1e-15);  // decoding darkens: linear <= encoded on 0..1
    previous = v;
  }
}
