// The job manifest (io/manifest.hpp): shards' layer ranges, scheduler environments, the JSON
// round trip and its refusals.
#include <catch2/catch.hpp>

#include <filesystem>
#include <map>
#include <vector>
#include <string>

#include "trivox/error.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/job/manifest.hpp"
#include "../io/io_test_util.hpp"

using namespace trivox;
using namespace trivox::io;
using namespace trivox::job;
using trivox::io::test::check_message;
using trivox::io::test::error_of;

namespace {

Manifest sample() {
  Manifest m;
  m.trivox = "0.1.0";
  m.model_file = "models/twisted_column.json";
  m.model_sha256 = std::string(64, 'a');
  m.options = {{"png.dpi", "600,300"}, {"png.layer_mm", "0.027"}, {"vdb.voxel_mm", "auto"}};
  m.grid = {10, 20, 30};
  m.dpi_x = 600;
  m.dpi_y = 300;
  m.layer_mm = 0.027;
  m.materials = {"VeroCyan-V", "VeroBlack"};
  m.colours = {{0, 137, 166, 255}, {26, 26, 29, 255}};
  m.shard = {1, 3};
  m.layer_range = m.shard.range(30);
  for (int k = m.layer_range[0]; k < m.layer_range[1]; k += 2)
    m.layers.push_back({k, "slice_" + std::to_string(k) + ".png", std::string(64, 'b'), {k, 2 * k}, k % 3});
  m.files = {{"vdb", "col.shard-1-of-3.vdb", std::string(64, 'c')}};
  return m;
}

// A fake environment for shard_from_environment.
std::map<std::string, std::string> env;
const char* fake_getenv(const char* name) {
  const auto it = env.find(name);
  return it == env.end() ? nullptr : it->second.c_str();
}

}  // namespace

TEST_CASE("shards cover every layer once, in contiguous ranges of whole 8-layer blocks", "[manifest]") {
  for (int nz = 0; nz <= 100; ++nz)
    for (int n = 1; n <= 12; ++n) {
      int expect = 0, smallest = 1 << 30, largest = 0;
      for (int k = 0; k < n; ++k) {
        const auto r = Shard{k, n}.range(nz);
        REQUIRE(r[0] == expect);  // contiguous, in order, from 0
        REQUIRE(r[1] >= r[0]);
        CHECK((r[0] % 8 == 0 || r[0] == nz));  // starts on a leaf boundary
        const int blocks = (r[1] - r[0] + 7) / 8;
        smallest = std::min(smallest, blocks);
        largest = std::max(largest, blocks);
        expect = r[1];
      }
      REQUIRE(expect == nz);                // the last one ends at the top
      CHECK(largest - smallest <= 1);       // as even as whole blocks allow
    }
  CHECK(Shard{0, 1}.range(17) == std::array<int, 2>{0, 17});
}

TEST_CASE("shard names and --shard K/N", "[manifest]") {
  CHECK(Shard{0, 1}.manifest_name() == "manifest.json");
  CHECK(Shard{2, 3}.manifest_name() == "manifest.shard-2-of-3.json");
  CHECK(Shard{0, 4}.part_name("teapot.vdb") == "teapot.shard-0-of-4.vdb");
  CHECK(Shard{0, 1}.part_name("teapot.vdb") == "teapot.vdb");
  CHECK(parse_shard("0/3") == Shard{0, 3});
  CHECK(parse_shard("2/3") == Shard{2, 3});
  for (const char* bad : {"3/3", "1", "-1/3", "1/0", "a/3", "1/3/4", "", "1/", "/3", "1/1000000", " 1/3"})
    CHECK_THAT(error_of([&] { parse_shard(bad); }), Catch::Contains("expected K/N with 0 <= K < N"));
}

TEST_CASE("the shard from a scheduler's environment; explicit values checked", "[manifest]") {
  env.clear();
  CHECK(!shard_from_environment(std::nullopt, fake_getenv));
  CHECK(!shard_from_environment(4, fake_getenv));

  // Slurm: an array 5-7 is task ids 5, 6, 7 with count 3.
  env = {{"SLURM_ARRAY_TASK_ID", "6"}, {"SLURM_ARRAY_TASK_MIN", "5"}, {"SLURM_ARRAY_TASK_COUNT", "3"}};
  CHECK(shard_from_environment(std::nullopt, fake_getenv) == Shard{1, 3});
  env = {{"SLURM_ARRAY_TASK_ID", "2"}, {"SLURM_ARRAY_TASK_COUNT", "4"}};
  CHECK(shard_from_environment(std::nullopt, fake_getenv) == Shard{2, 4});
  env = {{"SLURM_ARRAY_TASK_ID", "9"}, {"SLURM_ARRAY_TASK_MIN", "5"}, {"SLURM_ARRAY_TASK_COUNT", "3"}};
  CHECK_THAT(error_of([] { shard_from_environment(std::nullopt, fake_getenv); }), Catch::Contains("expected 0 to 2"));
  env = {{"SLURM_ARRAY_TASK_ID", "1"}};
  CHECK_THAT(error_of([] { shard_from_environment(std::nullopt, fake_getenv); }),
             Catch::Contains("SLURM_ARRAY_TASK_COUNT is not"));
  env = {{"SLURM_ARRAY_TASK_ID", "x"}, {"SLURM_ARRAY_TASK_COUNT", "3"}};
  CHECK_THAT(error_of([] { shard_from_environment(std::nullopt, fake_getenv); }),
             Catch::Contains("SLURM_ARRAY_TASK_ID=\"x\": expected an integer"));

  // Kubernetes Indexed Job: the index from the environment, the count from --shard-count.
  env = {{"JOB_COMPLETION_INDEX", "3"}};
  CHECK(shard_from_environment(5, fake_getenv) == Shard{3, 5});
  CHECK_THAT(error_of([] { shard_from_environment(std::nullopt, fake_getenv); }), Catch::Contains("--shard-count N"));
  CHECK_THAT(error_of([] { shard_from_environment(3, fake_getenv); }), Catch::Contains("expected 0 to 2"));
  CHECK_THAT(error_of([] { shard_from_environment(0, fake_getenv); }), Catch::Contains("--shard-count 0"));
  env.clear();
}

TEST_CASE("a manifest survives its JSON round trip exactly", "[manifest]") {
  const Manifest m = sample();
  const std::string text = manifest_json(m);
  const Manifest back = parse_manifest(text, "m.json");
  CHECK(back.trivox == m.trivox);
  CHECK(back.model_file == m.model_file);
  CHECK(back.model_sha256 == m.model_sha256);
  CHECK(back.options == m.options);
  CHECK(back.grid == m.grid);
  CHECK(back.dpi_x == m.dpi_x);
  CHECK(back.dpi_y == m.dpi_y);
  CHECK(back.layer_mm == m.layer_mm);
  CHECK(back.materials == m.materials);
  CHECK(back.colours == m.colours);
  CHECK(back.shard == m.shard);
  CHECK(back.layer_range == m.layer_range);
  CHECK(back.layers == m.layers);
  CHECK(back.files == m.files);
  CHECK(back.complete == m.complete);
  CHECK(manifest_json(back) == text);
  CHECK(back.same_job(m));
  REQUIRE(back.layer(m.layers[1].index));
  CHECK(*back.layer(m.layers[1].index) == m.layers[1]);
  CHECK(!back.layer(m.layers[0].index + 1));  // odd offsets were never listed
}

TEST_CASE("same_job compares everything that changes the outputs, and says what differs", "[manifest]") {
  const Manifest m = sample();
  Manifest o = m;
  o.layers.clear();  // progress is not identity
  o.complete = true;
  CHECK(m.same_job(o));
  o = m;
  o.model_sha256 = std::string(64, 'd');
  CHECK_THAT(m.difference(o), Catch::Contains("model's SHA-256"));
  o = m;
  o.options["png.dpi"] = "600,600";
  CHECK_THAT(m.difference(o), Catch::Contains("option png.dpi was 600,600, now 600,300"));
  o = m;
  o.options.erase("vdb.voxel_mm");
  CHECK_THAT(m.difference(o), Catch::Contains("vdb.voxel_mm"));
  o = m;
  o.trivox = "0.0.9";
  CHECK_THAT(m.difference(o), Catch::Contains("trivox 0.0.9"));
  o = m;
  o.colours[0][0] = 1;
  CHECK_THAT(m.difference(o), Catch::Contains("materials differ"));
}

TEST_CASE("malformed manifests are refused with the place and what was expected", "[manifest]") {
  const std::string good = manifest_json(sample());
  auto edit = [&](const std::string& from, const std::string& to) {
    std::string t = good;
    const auto at = t.find(from);
    REQUIRE(at != std::string::npos);
    t.replace(at, from.size(), to);
    return error_of([&] { parse_manifest(t, "m.json"); });
  };
  CHECK_THAT(error_of([] { parse_manifest("{", "m.json"); }), Catch::Contains("m.json: line 1, column 2: malformed JSON"));
  CHECK_THAT(error_of([] { parse_manifest("[]", "m.json"); }), Catch::Contains("m.json: top level: found an array"));
  CHECK_THAT(edit("\"trivox_manifest\": 1", "\"trivox_manifest\": 2"), Catch::Contains("/trivox_manifest"));
  CHECK_THAT(edit("\"sha256\": \"aaaa", "\"sha256\": \"Aaaa"), Catch::Contains("/model/sha256: found the string"));
  CHECK_THAT(edit("\"index\": 1,\n    \"count\": 3", "\"index\": 3,\n    \"count\": 3"), Catch::Contains("/shard/index"));
  CHECK_THAT(edit("\"complete\": false", "\"complete\": 0"), Catch::Contains("/complete: found the number 0; expected true or false"));
  // Shard 1 of 3 of 30 layers: [8, 16), listing layers 8, 10, 12 and 14.
  CHECK_THAT(edit("\"file\": \"slice_8.png\"", "\"file\": \"../x.png\""), Catch::Contains("/layers/0/file"));
  CHECK_THAT(edit("\"index\": 10", "\"index\": 8"), Catch::Contains("/layers/1/index"));  // not ascending
  CHECK_THAT(edit("\"index\": 8", "\"index\": 7"), Catch::Contains("/layers/0/index"));   // outside the range
  CHECK_THAT(edit("\"layer_range\": [\n    8,", "\"layer_range\": [\n    -1,"), Catch::Contains("/layer_range/0"));
  CHECK_THAT(edit("\"voxels\": [\n        8,", "\"voxels\": [\n"), Catch::Contains("/layers/0/voxels: found an array of 1"));
}

TEST_CASE("a PNG job's manifest records names, void and channels; earlier ones read as what they were", "[manifest]") {
  Manifest m = sample();
  m.options["png"] = "yes";
  SECTION("a manifest without them is one of the padded, transparent stacks of earlier trivox") {
    const Manifest back = parse_manifest(manifest_json(m), "manifest.json");
    CHECK(back.options.at("png.digits") == "5");
    CHECK(back.options.at("png.background") == "transparent");
    CHECK(back.options.at("png.channels") == "6");
    const io::StackConfig c = stack_config_of(back, {});
    CHECK(c.slice_name(0) == "slice_00000.png");
    CHECK(c.background == std::array<std::uint8_t, 4>{0, 0, 0, 0});
  }
  SECTION("recorded values drive the ConfigFile.xml, which lists the used materials only") {
    m.options["png.digits"] = "0";
    m.options["png.background"] = "black";
    m.options["png.channels"] = "7";
    m.layer_mm = 0.001001;  // 1000.9999999999999 nm in binary: written as 1001
    const io::StackConfig c = stack_config_of(parse_manifest(manifest_json(m), "manifest.json"), {0, 42});
    CHECK(c.slice_name(7) == "slice_7.png");
    CHECK(c.background == std::array<std::uint8_t, 4>{0, 0, 0, 255});
    CHECK(c.max_colors == 7);
    CHECK(c.slice_thickness_nm == 1001);
    REQUIRE(c.materials.size() == 1);
    CHECK(c.materials[0].name == "VeroBlack");
    CHECK(c.materials[0].voxel_count == 42);
    CHECK(io::config_xml(c).find("<SliceThicknessNanoMeter>1001</SliceThicknessNanoMeter>") != std::string::npos);
  }
  SECTION("malformed values are refused with their place") {
    m.options["png.digits"] = "12";
    check_message(error_of([&] { parse_manifest(manifest_json(m), "m.json"); }),
                  {"m.json: /options/png.digits: found the string \"12\"; expected a digit count 0..9"});
    m.options["png.digits"] = "0";
    m.options["png.background"] = "white";
    check_message(error_of([&] { parse_manifest(manifest_json(m), "m.json"); }),
                  {"/options/png.background", "expected \"transparent\" or \"black\""});
  }
}

TEST_CASE("names that become paths are the ones trivox writes, inside the folder", "[manifest]") {
  // sample(): shard 1 of 3, its VDB part col.shard-1-of-3.vdb.
  const auto refusal = [](const std::vector<ManifestFile>& files) {
    Manifest m = sample();
    m.files = files;
    return error_of([&] { parse_manifest(manifest_json(m), "m.json"); });
  };
  const std::string sha(64, 'c');
  for (const char* bad : {"../outside/victim.vdb", "/etc/shadow", "a/b.vdb", "..", ".", "", "a\\b.vdb"})
    check_message(refusal({{"vdb", bad, sha}}), {"m.json: /files/0/file: found the string", "expected a file name inside the folder"});
  // A NUL inside the name (JSON "\u0000").
  {
    std::string t = manifest_json(sample());
    const std::string from = "\"col.shard-1-of-3.vdb\"";
    t.replace(t.find(from), from.size(), "\"col\\u0000.shard-1-of-3.vdb\"");
    check_message(error_of([&] { parse_manifest(t, "m.json"); }), {"/files/0/file", "expected a file name inside the folder"});
  }
  check_message(refusal({{"config", "ConfigFile.xml", sha}, {"vdb", "../x", sha}}),
                {"m.json: /files/1/file: found the string \"../x\"; expected a file name inside the folder"});
  // Plain names, but not what trivox writes for the role.
  check_message(refusal({{"vdb", "notes.txt", sha}}), {"/files/0/file", "expected a VDB named <model>.shard-1-of-3.vdb"});
  check_message(refusal({{"vdb", "col.shard-0-of-3.vdb", sha}}), {"/files/0/file", "<model>.shard-1-of-3.vdb"});
  check_message(refusal({{"vdb", ".shard-1-of-3.vdb", sha}}), {"/files/0/file"});
  check_message(refusal({{"config", "notes.txt", sha}}), {"/files/0/file", "\"ConfigFile.xml\" for role config"});
  check_message(refusal({{"zip", "x.gcvf", sha}}), {"/files/0/file", "\"../<folder>.gcvf\""});
  check_message(refusal({{"zip", "../../x.gcvf", sha}}), {"/files/0/file", "\"../<folder>.gcvf\""});
  check_message(refusal({{"zip", "/tmp/x.gcvf", sha}}), {"/files/0/file"});
  check_message(refusal({{"model", "x.json", sha}}), {"/files/0/role", "expected \"config\", \"vdb\", \"zip\" or \"mesh\""});
  check_message(refusal({{"mesh", "model.stl", sha}}), {"/files/0/file", "\"Mesh.stl\" for role mesh"});
  check_message(refusal({{"vdb", "col.shard-1-of-3.vdb", sha}, {"vdb", "col.shard-1-of-3.vdb", sha}}),
                {"/files/1/role", "each role once"});
  // What trivox writes reads back.
  Manifest m = sample();
  m.files = {{"config", "ConfigFile.xml", sha}, {"zip", "../col.gcvf", sha}, {"vdb", "col.shard-1-of-3.vdb", sha}};
  CHECK(parse_manifest(manifest_json(m), "m.json").files == m.files);
  // Layers: slice_<k>.png of their own index, padded or not.
  const auto layer_refusal = [](const std::string& name) {
    Manifest m = sample();
    m.layers[0].file = name;
    return error_of([&] { parse_manifest(manifest_json(m), "m.json"); });
  };
  check_message(layer_refusal("../slice_8.png"), {"/layers/0/file", "expected a file name inside the folder"});
  check_message(layer_refusal("notes.txt"), {"/layers/0/file", "expected slice_8.png (zero-padded or not)"});
  check_message(layer_refusal("slice_9.png"), {"/layers/0/file", "expected slice_8.png"});
  m = sample();
  m.layers[0].file = "slice_00008.png";
  CHECK(parse_manifest(manifest_json(m), "m.json").layers[0].file == "slice_00008.png");
}

TEST_CASE("derived names: the whole VDB from the model's name, the archive from the folder's", "[manifest]") {
  Manifest m = sample();
  CHECK(vdb_file_name(m) == "twisted_column.vdb");
  m.model_file = "";
  CHECK(vdb_file_name(m) == "model.vdb");
  m.model_file = "/some/where/../teapot.json";
  CHECK(vdb_file_name(m) == "teapot.vdb");
  CHECK(zip_entry_name("jobs/teapot") == "../teapot.gcvf");
  CHECK(zip_entry_name("jobs/teapot/") == "../teapot.gcvf");
}

TEST_CASE("a journal adds the layers finished after its manifest, and only to that manifest", "[manifest][journal]") {
  Manifest m = sample();
  m.complete = false;
  const std::vector<ManifestLayer> all = m.layers;  // layers 8, 10, 12, 14 of shard 1 of 3
  REQUIRE(all.size() >= 4);
  // The manifest written at the start lists the first layer; the journal the others, in the
  // order they finished (not ascending), one of them twice (the later line wins).
  Manifest start = m;
  start.layers = {all[0]};
  const std::string text = manifest_json(start);
  ManifestLayer redone = all[2];
  redone.sha256 = std::string(64, 'd');
  const std::string journal = journal_header(text) + journal_line(all[3]) + journal_line(all[2]) +
                              journal_line(all[1]) + journal_line(redone);

  SECTION("every whole line of a journal of this manifest") {
    Manifest read = parse_manifest(text, "m.json");
    CHECK(apply_journal(read, text, journal) == 3);
    Manifest expect = m;
    expect.layers[2] = redone;
    CHECK(read.layers == expect.layers);
    CHECK(manifest_json(read) == manifest_json(expect));
  }
  SECTION("a last line cut short by a kill is left out, and so is everything after a damaged line") {
    Manifest read = parse_manifest(text, "m.json");
    const std::string cut = journal.substr(0, journal.size() - 10);
    CHECK(apply_journal(read, text, cut) == 3);  // all[3], all[2], all[1]; redone cut
    CHECK(read.layer(all[2].index)->sha256 == all[2].sha256);

    Manifest read2 = parse_manifest(text, "m.json");
    const std::string damaged = journal_header(text) + journal_line(all[3]) + "{\"index\": 1\n" + journal_line(all[1]);
    CHECK(apply_journal(read2, text, damaged) == 1);
    CHECK(read2.layers.size() == 2);
    // A line naming a layer outside the shard's range, or another file name, ends the journal.
    Manifest read3 = parse_manifest(text, "m.json");
    ManifestLayer outside = all[1];
    outside.index = m.layer_range[1];
    outside.file = "slice_" + std::to_string(outside.index) + ".png";
    ManifestLayer escaping = all[1];
    escaping.file = "../slice_" + std::to_string(escaping.index) + ".png";
    CHECK(apply_journal(read3, text, journal_header(text) + journal_line(outside) + journal_line(all[1])) == 0);
    CHECK(apply_journal(read3, text, journal_header(text) + journal_line(escaping)) == 0);
    CHECK(read3.layers.size() == 1);
  }
  SECTION("a journal of another manifest, or of a complete one, adds nothing") {
    Manifest other = start;
    other.model_sha256 = std::string(64, 'e');
    const std::string other_text = manifest_json(other);
    Manifest read = parse_manifest(text, "m.json");
    CHECK(apply_journal(read, text, journal_header(other_text) + journal_line(all[1])) == 0);
    CHECK(apply_journal(read, text, journal_line(all[1]) + journal_line(all[2])) == 0);  // no header
    CHECK(apply_journal(read, text, "") == 0);
    CHECK(read.layers.size() == 1);
    Manifest done = start;
    done.complete = true;
    const std::string done_text = manifest_json(done);
    Manifest read_done = parse_manifest(done_text, "m.json");
    CHECK(apply_journal(read_done, done_text, journal_header(done_text) + journal_line(all[1])) == 0);
  }
  SECTION("read_manifest applies the journal beside the manifest") {
    const io::test::TempDir tmp("journal");
    const auto& dir = tmp.path();
    io::write_file_atomically(dir / m.shard.manifest_name(), text);
    io::write_file_atomically(dir / m.shard.journal_name(), journal);
    CHECK(m.shard.journal_name() == "manifest.shard-1-of-3.journal");
    CHECK(journal_name_of("manifest.json") == "manifest.journal");
    const auto read = read_manifest(dir, m.shard.manifest_name());
    REQUIRE(read);
    CHECK(read->layers.size() == all.size());
    // A journal that is a link is left out.
    std::filesystem::remove(dir / m.shard.journal_name());
    io::write_file_atomically(dir / "elsewhere", journal);
    std::filesystem::create_symlink("elsewhere", dir / m.shard.journal_name());
    CHECK(read_manifest(dir, m.shard.manifest_name())->layers.size() == 1);
  }
}
