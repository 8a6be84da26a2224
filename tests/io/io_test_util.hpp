/// @file tests/io/io_test_util.hpp
/// @brief Helpers shared by the io tests: catching a trivox::Error and checking its message.
#pragma once
#include <catch2/catch.hpp>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string>
#include <string_view>

#include "trivox/error.hpp"

namespace trivox::io::test {

/// The message of the trivox::Error that `f` throws (checked to be bad_input); fails the test
/// when `f` returns normally. Any other exception escapes and fails the test too.
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const trivox::Error& e) {
    CHECK(e.kind() == trivox::ErrorKind::bad_input);
    return e.what();
  }
  FAIL("expected a trivox::Error");
  return {};
}

/// Checks that `message` names every one of `parts` (file, place, "expected", ...).
inline void check_message(const std::string& message, std::initializer_list<std::string_view> parts) {
  INFO("message: " << message);
  for (std::string_view p : parts) CHECK_THAT(message, Catch::Contains(std::string(p)));
}

inline std::filesystem::path source_dir() { return TRIVOX_SOURCE_DIR; }

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  REQUIRE(in);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A fresh empty folder under the system's temporary folder, removed at scope exit.
class TempDir {
public:
  explicit TempDir(const std::string& tag) {
    path_ = std::filesystem::temp_directory_path() /
            ("trivox-io-test-" + tag + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

private:
  std::filesystem::path path_;
};

}  // namespace trivox::io::test
