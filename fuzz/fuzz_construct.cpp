// libFuzzer harness: the input files of `trivox construct` (io::read_construct_input,
// docs/cli.md). Only reading: the constructors' cost grows with the splines by design.
#include "fuzz_target.hpp"
#include "trivox/io/construct_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return trivox::fuzz::run(data, size, [](std::string_view text) { trivox::io::read_construct_input(text, "construct.json"); });
}
