/// @file fuzz/fuzz_target.hpp
/// @brief The common body of the libFuzzer harnesses (docs/testing.md): one reader of trivox,
/// given the fuzzer's bytes as a whole file.
///
/// A reader may refuse its input only with trivox::Error (docs/architecture.md, "No input,
/// however malformed, crashes trivox"). Anything else is a finding: another exception type is
/// reported and aborts (so libFuzzer saves the input as a crash), as do a crash, a sanitizer
/// report, a timeout (-timeout) or memory beyond -rss_limit_mb.
///
/// Cost: one call of the reader per input.
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string_view>
#include <typeinfo>

#include "trivox/error.hpp"

namespace trivox::fuzz {

/// Runs `read(text)` on the fuzzer's bytes as text; returns 0 (libFuzzer keeps the input in its
/// corpus when it adds coverage). Aborts on any exception but trivox::Error.
template <class Read>
int run(const std::uint8_t* data, std::size_t size, Read&& read) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    read(text);
  } catch (const trivox::Error&) {
    // The reader refused the input, as it must for a malformed one.
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz: %s escaped the reader: %s; expected trivox::Error\n", typeid(e).name(),
                 e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "fuzz: a non-standard exception escaped the reader; expected trivox::Error\n");
    std::abort();
  }
  return 0;
}

}  // namespace trivox::fuzz
