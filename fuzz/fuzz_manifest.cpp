// libFuzzer harness: a print job's manifest (job::parse_manifest, docs/jobs.md), read by
// `trivox slice --resume` and `trivox merge`. A manifest it accepts must write and read back equal
// in identity and layers.
#include <cstdio>
#include <cstdlib>

#include "fuzz_target.hpp"
#include "trivox/job/manifest.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return trivox::fuzz::run(data, size, [](std::string_view text) {
    const trivox::job::Manifest m = trivox::job::parse_manifest(text, "manifest.json");
    trivox::job::Manifest back;
    try {
      back = trivox::job::parse_manifest(trivox::job::manifest_json(m), "written.json");
    } catch (const trivox::Error& e) {
      std::fprintf(stderr, "fuzz: a manifest read, written and read again was refused: %s\n", e.what());
      std::abort();
    }
    if (!m.same_job(back) || back.layers != m.layers || back.files != m.files || back.complete != m.complete) {
      std::fprintf(stderr, "fuzz: the manifest written and read back differs: %s\n", m.difference(back).c_str());
      std::abort();
    }
  });
}
