// libFuzzer harness: the scene reader of `trivox build` (scene::read_scene_json; load_scene reads
// the file and calls it). Building (scene::build_scene) is not fuzzed: it constructs geometry
// whose cost grows with the parameters by design. A "gismo" surface names a file relative to the
// working folder: the seed scenes name none, and a mutated name most likely names no file.
#include "fuzz_target.hpp"
#include "trivox/scene/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return trivox::fuzz::run(data, size, [](std::string_view text) { trivox::scene::read_scene_json(text, "fuzz.json"); });
}
