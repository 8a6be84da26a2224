// libFuzzer harness: the model JSON reader (io::read_model_json, docs/model-format.md). A model it
// accepts must also write and read back to the same model (the format's round trip); a model the
// writer refuses or that reads back different is a finding too.
#include <cstdio>
#include <cstdlib>

#include "fuzz_target.hpp"
#include "trivox/io/model_json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return trivox::fuzz::run(data, size, [](std::string_view text) {
    const trivox::vmodel::VModel model = trivox::io::read_model_json(text, "fuzz.json");
    std::string written;
    try {
      written = trivox::io::write_model_json(model);
    } catch (const trivox::Error& e) {
      std::fprintf(stderr, "fuzz: a model read was refused by the writer: %s\n", e.what());
      std::abort();
    }
    if (!(trivox::io::read_model_json(written, "written.json") == model)) {
      std::fprintf(stderr, "fuzz: the model written and read back differs from the model read\n");
      std::abort();
    }
  });
}
