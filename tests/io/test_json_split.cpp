// json_io::parse_split, the parallel parse of large documents, against nlohmann's one parse on
// random documents (every array split, whatever its size): equal DOMs whenever it answers, and
// never an answer for a document that is not valid JSON.
#include <catch2/catch.hpp>

#include <random>
#include <string>

#include "../../src/io/json_io.hpp"

namespace {

using nlohmann::json;

/// A random JSON value: nested arrays and objects, numbers of every kind, and strings holding
/// the characters a scanner must not take for structure ([ ] { } , : " \ and UTF-8).
json random_value(std::mt19937& rng, int depth) {
  std::uniform_int_distribution<int> kind(0, depth > 3 ? 3 : 6);
  static const char* strings[] = {"plain", "with [brackets] and {braces}", "a \"quote\" inside", "back\\slash\\",
                                  "comma, colon: done", "\xC3\xA9t\xC3\xA9", "", "]}],{\"", "\\\"[\\\\"};
  switch (kind(rng)) {
    case 0: return std::uniform_int_distribution<int>(-1000, 1000)(rng);
    case 1: return std::uniform_real_distribution<double>(-1e6, 1e6)(rng);
    case 2: return std::string(strings[std::uniform_int_distribution<int>(0, 8)(rng)]);
    case 3: return std::uniform_int_distribution<int>(0, 2)(rng) == 0 ? json(nullptr) : json(rng() % 2 == 0);
    case 4:
    case 5: {
      json a = json::array();
      const int n = std::uniform_int_distribution<int>(0, 4)(rng);
      for (int i = 0; i < n; ++i) a.push_back(random_value(rng, depth + 1));
      return a;
    }
    default: {
      json o = json::object();
      const int n = std::uniform_int_distribution<int>(0, 4)(rng);
      for (int i = 0; i < n; ++i) o[strings[std::uniform_int_distribution<int>(0, 8)(rng)]] = random_value(rng, depth + 1);
      return o;
    }
  }
}

/// A top-level object with a few array members (the split ones) and other values.
json random_document(std::mt19937& rng) {
  json doc = json::object();
  const int n = std::uniform_int_distribution<int>(1, 5)(rng);
  for (int i = 0; i < n; ++i) {
    const std::string key = "k" + std::to_string(i);
    if (rng() % 3 != 0) {
      json a = json::array();
      const int m = std::uniform_int_distribution<int>(0, 6)(rng);
      for (int e = 0; e < m; ++e) a.push_back(random_value(rng, 1));
      doc[key] = a;
    } else {
      doc[key] = random_value(rng, 1);
    }
  }
  return doc;
}

}  // namespace

TEST_CASE("the split parse equals the one parse, and refuses what is not JSON", "[io][json]") {
  using trivox::io::json_io::parse_split;
  std::mt19937 rng(2026);
  int answered = 0, refused_invalid = 0;
  for (int n = 0; n < 3000; ++n) {
    const json doc = random_document(rng);
    std::string text = doc.dump(static_cast<int>(rng() % 3) - 1);  // compact, or indented by 0 or 1
    if (rng() % 4 == 0) text = " \n" + text + "\t\n";
    // Half the documents corrupted by one byte: removed, doubled or replaced by a structural one.
    if (n % 2 == 1 && !text.empty()) {
      const std::size_t at = rng() % text.size();
      static const char structural[] = "[]{},:\"\\ 1";
      switch (rng() % 3) {
        case 0: text.erase(at, 1); break;
        case 1: text.insert(at, 1, text[at]); break;
        default: text[at] = structural[rng() % (sizeof structural - 1)]; break;
      }
    }
    const json want = json::parse(text, nullptr, /*allow_exceptions=*/false);
    const auto got = parse_split(text, 0);
    INFO("document " << n << ": " << text);
    if (want.is_discarded()) {
      CHECK_FALSE(got.has_value());
      ++refused_invalid;
    } else if (got) {
      CHECK((*got == want));
      ++answered;
    }
  }
  // Both branches ran often: the test is not vacuous.
  CHECK(answered > 1000);
  CHECK(refused_invalid > 500);
}
