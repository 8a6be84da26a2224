// SHA-256 of bytes and files against the FIPS 180-2 test vectors (Appendix B: "abc", the
// 448-bit two-block message, one million 'a') and the digest of the empty message.
#include "io_test_util.hpp"
#include "trivox/io/sha256.hpp"

namespace {

namespace fs = std::filesystem;
using trivox::io::sha256_file;
using trivox::io::sha256_hex;
using trivox::io::test::check_message;
using trivox::io::test::error_of;
using trivox::io::test::TempDir;

const std::string million_a(1'000'000, 'a');
constexpr const char* abc_digest = "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad";
constexpr const char* empty_digest = "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855";
constexpr const char* two_block_digest = "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1";
constexpr const char* million_a_digest = "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0";

void write_bytes(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary);
  out << bytes;
}

}  // namespace

TEST_CASE("sha256_hex gives the FIPS 180-2 digests", "[io][sha256]") {
  CHECK(sha256_hex("abc") == abc_digest);
  CHECK(sha256_hex("") == empty_digest);
  CHECK(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq") == two_block_digest);
  CHECK(sha256_hex(million_a) == million_a_digest);
}

TEST_CASE("sha256_hex hashes bytes, NUL included", "[io][sha256]") {
  const std::string with_nul("abc\0", 4);
  CHECK(sha256_hex(with_nul) != abc_digest);
  CHECK(sha256_hex(std::string_view("abcdef", 3)) == abc_digest);
}

TEST_CASE("sha256_file streams files of any size", "[io][sha256]") {
  TempDir dir("sha256");
  write_bytes(dir.path() / "empty", "");
  write_bytes(dir.path() / "abc", "abc");
  write_bytes(dir.path() / "million", million_a);
  // More than the 1 MiB read block: two blocks, the second partial.
  std::string big = million_a + million_a;
  write_bytes(dir.path() / "big", big);
  CHECK(sha256_file(dir.path() / "empty") == empty_digest);
  CHECK(sha256_file(dir.path() / "abc") == abc_digest);
  CHECK(sha256_file(dir.path() / "million") == million_a_digest);
  CHECK(sha256_file(dir.path() / "big") == sha256_hex(big));
}

TEST_CASE("sha256_file names a file it cannot read", "[io][sha256]") {
  TempDir dir("sha256-bad");
  const fs::path missing = dir.path() / "no-such-file.vdb";
  check_message(error_of([&] { sha256_file(missing); }), {missing.string(), "no such file", "expected a readable file"});
  check_message(error_of([&] { sha256_file(dir.path()); }), {dir.path().string(), "folder", "expected a readable file"});
  if (::geteuid() != 0) {  // root reads anything
    const fs::path locked = dir.path() / "locked";
    write_bytes(locked, "abc");
    fs::permissions(locked, fs::perms::none);
    check_message(error_of([&] { sha256_file(locked); }), {locked.string(), "expected a readable file"});
  }
}
