// Loading models from disk by content, saving them atomically, and the errors for files that
// are missing, unreadable or of no known format (fixtures in tests/data/bad).
#include <sys/stat.h>

#include "io_test_util.hpp"
#include "trivox/io/gismo_xml.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/io/model_json.hpp"

namespace {

namespace fs = std::filesystem;
using trivox::io::load_model;
using trivox::io::save_model;
using trivox::io::test::check_message;
using trivox::io::test::error_of;
using trivox::io::test::slurp;
using trivox::io::test::source_dir;
using trivox::io::test::TempDir;
using trivox::vmodel::VModel;

fs::path bad(const std::string& name) { return source_dir() / "tests" / "data" / "bad" / name; }
fs::path gismo(const std::string& name) { return source_dir() / "models" / "gismo" / name; }

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

std::vector<std::string> folder_entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

TEST_CASE("load_model picks the reader by content", "[io][file]") {
  for (const char* name : {"cube.xml", "fichera.xml", "teapot.xml"}) {
    const fs::path p = gismo(name);
    CHECK(load_model(p) == trivox::io::read_gismo_xml(slurp(p), p.string()));
  }
  TempDir dir("detect");
  const VModel cube = load_model(gismo("cube.xml"));
  // JSON under an .xml name, after a byte-order mark and blank lines: still JSON.
  const fs::path odd = dir.path() / "actually-json.xml";
  write_text(odd, "\xEF\xBB\xBF\n \t\r\n" + trivox::io::write_model_json(cube));
  CHECK(load_model(odd) == cube);
}

TEST_CASE("missing and unreadable files", "[io][file][bad]") {
  TempDir dir("missing");
  const fs::path nothing = dir.path() / "nothing.json";
  check_message(error_of([&] { load_model(nothing); }),
                {nothing.string() + ": no such file; expected an existing model file"});
  check_message(error_of([&] { load_model(dir.path()); }),
                {dir.path().string() + ": is a folder; expected a model file"});
  if (::geteuid() != 0) {  // root reads files whatever their mode
    const fs::path locked = dir.path() / "locked.json";
    write_text(locked, "{}");
    fs::permissions(locked, fs::perms::none);
    check_message(error_of([&] { load_model(locked); }),
                  {locked.string() + ": cannot open: Permission denied; expected a readable file"});
  }
}

TEST_CASE("files of no known format", "[io][file][bad]") {
  check_message(error_of([] { load_model(bad("empty.json")); }),
                {bad("empty.json").string() + ": the file is empty; expected a trivox JSON model"});
  check_message(error_of([] { load_model(bad("not_a_model.stl")); }),
                {bad("not_a_model.stl").string() + ": the file starts with 's'; expected a trivox JSON model (starting with '{') or G+Smo XML (starting with '<')"});
  check_message(error_of([] { trivox::io::read_model("\x01\x02", "bin.dat"); }),
                {"bin.dat: the file starts with byte 1; expected"});
}

TEST_CASE("bad fixture files give messages with file, place and expectation", "[io][file][bad]") {
  check_message(error_of([] { load_model(bad("truncated.json")); }),
                {bad("truncated.json").string() + ": line 19, column 1: malformed JSON", "expected"});
  check_message(error_of([] { load_model(bad("scene.json")); }),
                {bad("scene.json").string() + ": /cells/0/primitive: this is a scene", "expected", "trivox build"});
  check_message(error_of([] { load_model(bad("bad_points.json")); }),
                {bad("bad_points.json").string() + ": /cells/0/trivariate/points/6: 3 coordinates; expected 4 (xyz + 1 property)"});
  check_message(error_of([] { load_model(bad("bad_knots.xml")); }),
                {bad("bad_knots.xml").string() +
                     ": Geometry[0] (id=\"0\") / Basis type=\"TensorBSplineBasis3\" / Basis index=\"1\" / "
                     "KnotVector (line 10): knot 3 (0.5) is less than knot 2 (1); expected non-decreasing knots"});
}

TEST_CASE("save_model writes a file load_model reads back", "[io][file]") {
  TempDir dir("save");
  const VModel teapot = load_model(gismo("teapot.xml"));
  const fs::path p = dir.path() / "teapot.json";
  save_model(teapot, p);
  CHECK(load_model(p) == teapot);
  CHECK(folder_entries(dir.path()) == std::vector<std::string>{"teapot.json"});  // no leftovers

  // Replacing an existing file.
  const VModel cube = load_model(gismo("cube.xml"));
  save_model(cube, p);
  CHECK(load_model(p) == cube);
  CHECK(folder_entries(dir.path()) == std::vector<std::string>{"teapot.json"});
}

TEST_CASE("save_model leaves the old file untouched when it cannot write", "[io][file][bad]") {
  TempDir dir("save-bad");
  const fs::path p = dir.path() / "model.json";
  const VModel cube = load_model(gismo("cube.xml"));
  save_model(cube, p);
  const std::string before = slurp(p);

  VModel broken = cube;
  broken.properties.push_back("density");  // cells now lack a coordinate
  check_message(error_of([&] { save_model(broken, p); }),
                {p.string() + ": cannot write the model: \"patch0\" has 3 coordinates per control point; expected 4"});
  CHECK(slurp(p) == before);
  CHECK(folder_entries(dir.path()) == std::vector<std::string>{"model.json"});

  const fs::path nowhere = dir.path() / "no" / "such" / "folder" / "model.json";
  check_message(error_of([&] { save_model(cube, nowhere); }),
                {nowhere.string() + ": cannot write: folder", "does not exist; expected an existing, writable folder"});
  check_message(error_of([&] { save_model(cube, dir.path()); }),
                {dir.path().string() + ": is a folder; expected a file path"});
  check_message(error_of([&] { save_model(cube, dir.path() / "model.xml"); }),
                {"model.xml: an .xml name; expected a .json name"});
}

TEST_CASE("the examples in docs/model-format.md load (or are scenes)", "[io][file][docs]") {
  const std::string doc = slurp(source_dir() / "docs" / "model-format.md");
  int models = 0, scenes = 0;
  for (const std::string fence : {"```json\n", "```xml\n"}) {
    for (auto at = doc.find(fence); at != std::string::npos; at = doc.find(fence, at + 1)) {
      const auto begin = at + fence.size();
      const std::string block = doc.substr(begin, doc.find("```", begin) - begin);
      try {
        const VModel m = trivox::io::read_model(block, "example");
        CHECK((m.cells.size() + m.surfaces.size()) > 0);
        ++models;
      } catch (const trivox::Error& e) {
        INFO(block);
        CHECK_THAT(std::string(e.what()), Catch::Contains("this is a scene"));
        ++scenes;
      }
    }
  }
  CHECK(models == 2);
  CHECK(scenes == 1);
}

TEST_CASE("coordinates of absurd magnitude are refused with their place") {
  const std::string text = R"({"trivox": 1, "cells": [{"name": "c", "trivariate": {"orders": [2, 2, 2],
    "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]],
    "points": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [0, 0, 1], [1, 0, 1], [0, 1, 1], [1, 1, 1e300]]}}]})";
  CHECK_THROWS_WITH(trivox::io::read_model(text, "big.json"),
                    Catch::Contains("big.json: /cells/0/trivariate/points/7/2") &&
                        Catch::Contains("expected a magnitude of at most 1e12"));
}
