// libFuzzer harness: a Voxel Print stack's ConfigFile.xml (io::parse_config_xml,
// docs/slice-output.md), read by `trivox inspect`, `preview` and `merge`.
#include "fuzz_target.hpp"
#include "trivox/io/stack_config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return trivox::fuzz::run(data, size, [](std::string_view text) { trivox::io::parse_config_xml(text, "ConfigFile.xml"); });
}
