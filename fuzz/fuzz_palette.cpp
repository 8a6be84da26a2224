// libFuzzer harness: palette files (slice::parse_palette, docs/materials.md), read by
// `trivox slice --palette`. A palette it accepts must write and read back equal
// (parse_palette(palette_json(p)) == p, as slice/material.hpp promises).
#include <cstdio>
#include <cstdlib>

#include "fuzz_target.hpp"
#include "trivox/slice/material.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return trivox::fuzz::run(data, size, [](std::string_view text) {
    const trivox::slice::Palette p = trivox::slice::parse_palette(text, "palette.json");
    trivox::slice::Palette back;
    try {
      back = trivox::slice::parse_palette(trivox::slice::palette_json(p), "written.json");
    } catch (const trivox::Error& e) {
      std::fprintf(stderr, "fuzz: a palette read, written and read again was refused: %s\n", e.what());
      std::abort();
    }
    if (!(back == p)) {
      std::fprintf(stderr, "fuzz: the palette written and read back differs\n");
      std::abort();
    }
  });
}
