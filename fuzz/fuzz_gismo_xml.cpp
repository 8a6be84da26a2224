// libFuzzer harness: the G+Smo XML reader (io::read_gismo_xml), through io::read_model, which
// picks the reader by the first character (so JSON inputs the mutations make reach the JSON
// reader too).
#include "fuzz_target.hpp"
#include "trivox/io/gismo_xml.hpp"
#include "trivox/io/model_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return trivox::fuzz::run(data, size, [](std::string_view text) { trivox::io::read_model(text, "fuzz.xml"); });
}
