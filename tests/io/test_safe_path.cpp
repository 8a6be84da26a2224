// Names from files kept inside their folder (io/safe_path.hpp): plain names, files read without
// following links, and the temporaries of killed runs.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "trivox/io/safe_path.hpp"
#include "trivox/io/sha256.hpp"
#include "io_test_util.hpp"

using namespace trivox::io;
using trivox::io::test::check_message;
using trivox::io::test::error_of;
using trivox::io::test::TempDir;
namespace fs = std::filesystem;

namespace {
void put(const fs::path& p, const std::string& bytes) { std::ofstream(p, std::ios::binary) << bytes; }
}  // namespace

TEST_CASE("plain file names stay in their folder", "[io][safe_path]") {
  for (const char* ok : {"slice_0.png", "manifest.json", "a b.vdb", "..x", ".hidden", "x.."}) CHECK(plain_file_name(ok));
  for (const char* bad : {"", ".", "..", "../x", "/etc/shadow", "a/b", "a\\b", "x/"}) CHECK(!plain_file_name(bad));
  CHECK(!plain_file_name(std::string("a\0b", 3)));
  CHECK(plain_file_name(std::string(255, 'a')));
  CHECK(!plain_file_name(std::string(256, 'a')));
}

TEST_CASE("files are hashed and read only when regular and not reached through a link", "[io][safe_path]") {
  TempDir dir("safe-path");
  const fs::path d = dir.path();
  put(d / "real", "abc");
  fs::create_symlink(d / "real", d / "link");
  fs::create_directory(d / "sub");
  CHECK(sha256_regular_file(d / "real") == sha256_hex("abc"));
  CHECK(!sha256_regular_file(d / "link"));  // same bytes, but a link: not trusted
  CHECK(!sha256_regular_file(d / "missing"));
  CHECK(!sha256_regular_file(d / "sub"));
  CHECK(regular_file_no_link(d / "real"));
  CHECK(!regular_file_no_link(d / "link"));
  CHECK(!regular_file_no_link(d / "sub"));
  CHECK(read_regular_file(d / "real", 3) == std::string("abc"));
  CHECK(!read_regular_file(d / "missing", 3));
  check_message(error_of([&] { read_regular_file(d / "link", 3); }), {"link: is a symbolic link; expected a regular file"});
  check_message(error_of([&] { read_regular_file(d / "real", 2); }), {"real: file size: 3 bytes; expected at most 2 bytes"});
  check_message(error_of([&] { read_regular_file(d / "sub", 2); }), {"sub: not a regular file"});
}

TEST_CASE("temporaries of atomic writes are recognised and removed for their owners only", "[io][safe_path]") {
  CHECK(temporary_owner(".slice_3.png.tmp-1234-7f3a9c-0") == std::string("slice_3.png"));
  CHECK(temporary_owner(".teapot.vdb.tmp-99-2") == std::string("teapot.vdb"));
  CHECK(temporary_owner(".manifest.json.tmp-1-ab-12") == std::string("manifest.json"));
  for (const char* not_one : {"slice_3.png", ".slice_3.png.tmp-", ".slice_3.png.tmp-12", ".x.tmp-12-zz-1", "x.tmp-1-2",
                              ".x.tmp-1-a-b-2", ".x.tmp--1", ".tmp-1-2"})
    CHECK(!temporary_owner(not_one));

  TempDir dir("safe-path-tmp");
  const fs::path d = dir.path();
  for (const char* f : {".slice_3.png.tmp-1234-7f3a9c-0", ".manifest.json.tmp-5-1", ".notes.txt.tmp-5-1", "slice_3.png", "notes.txt"})
    put(d / f, "x");
  fs::create_directory(d / ".slice_4.png.tmp-1-2");                      // a folder: stays
  fs::create_symlink(d / "notes.txt", d / ".slice_5.png.tmp-1-2");       // a link: stays
  const int removed = remove_stale_temporaries(d, [](const std::string& owner) { return owner != "notes.txt"; });
  CHECK(removed == 2);
  std::set<std::string> left;
  for (const auto& e : fs::directory_iterator(d)) left.insert(e.path().filename().string());
  CHECK(left == std::set<std::string>{".notes.txt.tmp-5-1", "slice_3.png", "notes.txt", ".slice_4.png.tmp-1-2", ".slice_5.png.tmp-1-2"});
}
