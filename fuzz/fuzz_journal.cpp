// libFuzzer harness: the journal of a running print job (job::apply_journal, docs/jobs.md), read
// with its manifest by `trivox slice --resume`, `trivox merge` and `trivox inspect`. The fuzzer's
// bytes are the journal's layer lines, read once as they are (a header that does not match) and
// once after the header of the manifest below (so the layer lines are reached). What it adds must
// keep the manifest one trivox writes and reads back: layers in ascending order, each index once,
// the manifest's own layers kept unless a journal line replaced them.
#include <cstdio>
#include <cstdlib>
#include <set>
#include <string>

#include "fuzz_target.hpp"
#include "trivox/job/manifest.hpp"

namespace {

// A manifest written at the start of an 11-layer job that had finished layers 0 and 1.
constexpr std::string_view manifest_text = R"json({"trivox_manifest":1,"trivox":"0.1.0",
"model":{"file":"graded_block.json","sha256":"86cbbde88859824055aa2e82fe4d83514b0f5e9cb05b9f4cf77cbc2ff2d3001d"},
"options":{"png":"yes","png.dither":"fs","png.dpi":"25,25","png.layer_mm":"4","png.palette":"vero (built in)",
"png.printer":"custom","png.zip":"no","vdb":"no"},
"grid":[40,20,11],"print":{"dpi":[25.0,25.0],"layer_mm":4.0},
"materials":[{"name":"VeroCyan-V","rgba":[0,137,166,255]},{"name":"VeroMagenta-V","rgba":[198,0,88,255]},
{"name":"VeroYellow-V","rgba":[240,197,0,255]},{"name":"VeroBlack","rgba":[26,26,29,255]},
{"name":"VeroUltraWhite","rgba":[255,255,255,255]},{"name":"UltraClear","rgba":[137,137,137,255]}],
"shard":{"index":0,"count":1},"layer_range":[0,11],"complete":false,
"files":[{"role":"config","file":"ConfigFile.xml","sha256":"3b6c74bcace1c3833f5e34f53ef81835e5ca9dc4ab8d77d93de82023d9c5bb11"}],
"layers":[{"index":0,"file":"slice_00000.png","sha256":"c615f99bcc4943431a37559d7d42e3a393bba11ec26e95fb9c5ab25759eb62ad","voxels":[0,287,493,0,0,0],"failures":0},
{"index":1,"file":"slice_00001.png","sha256":"2717194bd857844d72692c4057ff655df78192a22bd4cc990f90b237124ca90a","voxels":[0,303,473,0,4,0],"failures":0}]}
)json";

[[noreturn]] void fail(const char* what, const std::string& detail = "") {
  std::fprintf(stderr, "fuzz: journal: %s%s\n", what, detail.c_str());
  std::abort();
}

void check(std::string_view journal) {
  using namespace trivox::job;
  const Manifest start = parse_manifest(manifest_text, "manifest.json");
  Manifest m = start;
  const std::size_t added = apply_journal(m, manifest_text, journal);
  if (added > m.layers.size()) fail("more layers read than the manifest holds");
  std::set<int> indices;
  for (std::size_t i = 0; i < m.layers.size(); ++i) {
    if (i > 0 && m.layers[i].index <= m.layers[i - 1].index) fail("layers not in ascending order");
    indices.insert(m.layers[i].index);
  }
  for (const ManifestLayer& l : start.layers)
    if (!indices.count(l.index)) fail("a layer of the manifest was lost: ", std::to_string(l.index));
  if (added == 0 && m.layers != start.layers) fail("nothing read, yet the layers changed");
  if (!m.same_job(start) || m.files != start.files || m.complete) fail("the journal changed more than the layers");
  Manifest back;
  try {
    back = parse_manifest(manifest_json(m), "written.json");
  } catch (const trivox::Error& e) {
    fail("the manifest with its journal, written and read again, was refused: ", e.what());
  }
  if (back.layers != m.layers) fail("the layers of the manifest with its journal, written and read back, differ");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return trivox::fuzz::run(data, size, [](std::string_view text) {
    check(text);
    check(trivox::job::journal_header(manifest_text) + std::string(text));
  });
}
