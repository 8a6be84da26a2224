/// @file src/io/json_io.hpp
/// @brief Private to trivox_core (io, and scene's reader): checked reading of JSON documents and
/// writing of splines, shared by the model, scene and constructor files. Every value's type and
/// range is checked before it is used, and every failure is a trivox::Error (bad_input) reading
/// "<file>: <JSON pointer>: <what was found>; expected <what>" (or "<file>: line L, column C:
/// malformed JSON: ..." for syntax).
#pragma once
#include <tbb/parallel_for.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <array>
#include <atomic>
#include <optional>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "../detail/json_text.hpp"
#include "trivox/error.hpp"
#include "trivox/io/model_json.hpp"
#include "trivox/spline/tensor_spline.hpp"

namespace trivox::io::json_io {

using nlohmann::json;
using spline::KnotVector;

// ------------------------------------------------------------------------------------------
// Message pieces

/// The file being read: every message starts with its name and a JSON pointer.
struct Source {
  const std::string& name;

  [[noreturn]] void fail(const std::string& ptr, const std::string& what) const {
    throw Error(name + ": " + (ptr.empty() ? std::string("top level") : ptr) + ": " + what);
  }
  /// For wrapping errors thrown by lower layers (KnotVector, TensorSpline).
  std::string at(const std::string& ptr) const { return name + ": " + ptr; }
};

inline std::string child(const std::string& ptr, std::size_t i) { return ptr + "/" + std::to_string(i); }
inline std::string child(const std::string& ptr, const char* key) { return ptr + "/" + key; }

/// Shortest round-trip text of a double, always with a '.' or exponent so that a reader keeps it
/// a floating-point number (this is what keeps -0.0 negative through nlohmann's parser).
inline std::string format_double(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  std::string s(buf, r.ptr);
  if (s.find_first_of(".en") == std::string::npos) s += ".0";
  return s;
}

inline std::string quote(const std::string& s) { return detail::json_quote(s); }

inline std::string plural(std::int64_t n, const std::string& word) {
  return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
}

inline std::string describe(const json& j) { return detail::json_describe(j); }

[[noreturn]] inline void fail_type(const Source& src, const std::string& ptr, const json& j,
                            const std::string& expected) {
  src.fail(ptr, "found " + describe(j) + "; expected " + expected);
}

// ------------------------------------------------------------------------------------------
// Parsing with positions

/// nlohmann's DOM builder, but keeping the byte position of a failure: the library reports a
/// number overflow (1e999) without one, and the user needs a line to find it.
class PositionedParser : public nlohmann::detail::json_sax_dom_parser<json> {
public:
  explicit PositionedParser(json& root) : json_sax_dom_parser(root, false) {}

  template <class Exception>
  bool parse_error(std::size_t position, const std::string& token, const Exception& ex) {
    failed_ = true;
    message_ = ex.what();
    // A syntax error is placed at the last character read; an overflowing number at its start.
    const bool overflow = message_.find("number overflow") != std::string::npos;
    position_ = overflow && position > token.size() ? position - token.size() + 1 : position;
    return false;
  }

  bool failed() const noexcept { return failed_; }
  std::size_t position() const noexcept { return position_; }
  const std::string& message() const noexcept { return message_; }

private:
  bool failed_ = false;
  std::size_t position_ = 0;
  std::string message_;
};

/// The large documents' fast path (models of thousand-span cells run to 100 MB): the elements of
/// the top-level object's big arrays ("cells") parsed in parallel, each on its own, and put back
/// in order into the rest of the document, parsed without them. JSON values are context-free, so
/// this is the same DOM as one parse; it is taken only when every piece parses (then the whole is
/// valid: the pieces joined by commas inside their brackets) and the top-level keys are plain
/// and distinct. Otherwise nothing: the caller parses the whole (and reports its errors).
/// @param big  the arrays split: those spanning at least this many bytes
inline std::optional<json> parse_split(std::string_view text, std::size_t big = std::size_t{1} << 20) {
  struct Member {
    std::string key;
    std::size_t open = 0, close = 0;             // the array's brackets
    std::vector<std::pair<std::size_t, std::size_t>> items;  // element spans
  };
  std::vector<Member> members;
  std::vector<std::string> keys;
  int depth = 0;
  bool in_string = false, top_seen = false, expect_key = false;
  std::size_t string_start = 0, item_start = 0;
  Member* current = nullptr;  // the big array being split (depth 2 inside it)
  std::vector<char> opened;   // the open brackets and braces, innermost last
  std::string last_key;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') {
        if (depth == 1 && expect_key) return std::nullopt;  // escaped keys: the slow path
        ++i;
      } else if (c == '"') {
        in_string = false;
        if (depth == 1 && expect_key) {
          last_key.assign(text.substr(string_start + 1, i - string_start - 1));
          keys.push_back(last_key);
          expect_key = false;
        }
      }
      continue;
    }
    if (depth >= 3) {
      // Inside an element: only brackets, braces and quotes matter, and long runs of numbers
      // have none of them. Skip 16 bytes at a time that hold none (SSE2).
#if defined(__SSE2__)
      while (i + 16 <= text.size()) {
        const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(text.data() + i));
        // '[' 0x5b, ']' 0x5d, '{' 0x7b, '}' 0x7d: with bit 5 cleared, 0x5b or 0x5d; and '"'.
        const __m128i up = _mm_and_si128(v, _mm_set1_epi8(static_cast<char>(0xdf)));
        const __m128i hit = _mm_or_si128(_mm_or_si128(_mm_cmpeq_epi8(up, _mm_set1_epi8(0x5b)), _mm_cmpeq_epi8(up, _mm_set1_epi8(0x5d))),
                                         _mm_cmpeq_epi8(v, _mm_set1_epi8('"')));
        const int mask = _mm_movemask_epi8(hit);
        if (mask != 0) {
          i += static_cast<std::size_t>(__builtin_ctz(static_cast<unsigned>(mask)));
          break;
        }
        i += 16;
      }
      if (i >= text.size()) break;
#endif
    }
    const char c2 = text[i];
    switch (c2) {
      case '"':
        in_string = true;
        string_start = i;
        break;
      case '{':
      case '[':
        if (depth == 0) {
          if (c2 != '{' || top_seen) return std::nullopt;
          top_seen = expect_key = true;
        } else if (depth == 1 && c2 == '[') {
          members.push_back({last_key, i, 0, {}});
          current = &members.back();
          item_start = i + 1;
        }
        opened.push_back(c2);
        ++depth;
        break;
      case '}':
      case ']':
        // Brackets must match (else the document is not JSON, and the spans would be nonsense).
        if (opened.empty() || opened.back() != (c2 == '}' ? '{' : '[')) return std::nullopt;
        opened.pop_back();
        if (depth == 2 && current && c2 == ']') {
          current->items.emplace_back(item_start, i);
          current->close = i;
          current = nullptr;
        }
        if (--depth < 0) return std::nullopt;
        break;
      case ',':
        if (depth == 1) expect_key = true;
        if (depth == 2 && current) {
          current->items.emplace_back(item_start, i);
          item_start = i + 1;
        }
        break;
      default:
        break;
    }
  }
  if (depth != 0 || in_string || !top_seen) return std::nullopt;
  std::vector<std::string> sorted = keys;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) return std::nullopt;
  // Split only the big arrays; an empty one ("[]", one blank item) stays in the rest.
  std::erase_if(members, [&](const Member& m) {
    return m.close - m.open < big || (m.items.size() == 1 && text.substr(m.items[0].first, m.items[0].second - m.items[0].first)
                                                                     .find_first_not_of(" \t\n\r") == std::string_view::npos);
  });
  if (members.empty()) return std::nullopt;
  std::string rest;
  std::size_t at = 0;
  for (const auto& m : members) {
    rest.append(text.substr(at, m.open + 1 - at));
    at = m.close;
  }
  rest.append(text.substr(at));
  std::vector<std::pair<std::size_t, std::size_t>> spans;
  for (const auto& m : members) spans.insert(spans.end(), m.items.begin(), m.items.end());
  std::vector<json> parsed(spans.size());
  std::atomic<bool> ok{true};
  tbb::parallel_for(std::size_t{0}, spans.size(), [&](std::size_t k) {
    const auto piece = text.substr(spans[k].first, spans[k].second - spans[k].first);
    parsed[k] = json::parse(piece.begin(), piece.end(), nullptr, /*allow_exceptions=*/false);
    if (parsed[k].is_discarded()) ok = false;
  });
  if (!ok) return std::nullopt;
  json root = json::parse(rest, nullptr, /*allow_exceptions=*/false);
  if (root.is_discarded() || !root.is_object()) return std::nullopt;
  std::size_t k = 0;
  for (const auto& m : members) {
    json& a = root[m.key];
    if (!a.is_array() || !a.empty()) return std::nullopt;
    auto& arr = a.get_ref<json::array_t&>();
    arr.reserve(m.items.size());
    for (std::size_t e = 0; e < m.items.size(); ++e) arr.push_back(std::move(parsed[k++]));
  }
  return root;
}

inline json parse(const Source& src, std::string_view text) {
  if (text.size() >= (std::size_t{8} << 20))
    if (auto fast = parse_split(text)) return std::move(*fast);
  json root;
  PositionedParser parser(root);
  json::sax_parse(text.begin(), text.end(), &parser, nlohmann::detail::input_format_t::json,
                  /*strict=*/true, /*ignore_comments=*/false);
  if (parser.failed())
    throw Error(src.name + ": " + detail::json_line_column(text, parser.position()) +
                ": malformed JSON: " + detail::json_parse_message(parser.message()));
  return root;
}

// ------------------------------------------------------------------------------------------
// Typed access: every value's type is checked before it is read

inline const json* find(const json& object, const char* key) {
  const auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

inline const json& require(const Source& src, const json& object, const std::string& ptr, const char* key,
                    const std::string& expected) {
  if (const json* j = find(object, key)) return *j;
  src.fail(ptr, std::string("missing \"") + key + "\"; expected " + expected);
}

inline const json& expect_object(const Source& src, const json& j, const std::string& ptr,
                          const std::string& expected) {
  if (!j.is_object()) fail_type(src, ptr, j, expected);
  return j;
}

inline const json& expect_array(const Source& src, const json& j, const std::string& ptr,
                         const std::string& expected) {
  if (!j.is_array()) fail_type(src, ptr, j, expected);
  return j;
}

inline double read_number(const Source& src, const json& j, const std::string& ptr) {
  if (!j.is_number()) fail_type(src, ptr, j, "a number");
  const double v = j.get<double>();
  // The parser rejects overflowing literals; this guards models built by other means.
  if (!std::isfinite(v)) src.fail(ptr, "found " + format_double(v) + "; expected a finite number");
  return v;
}

/// read_number of element i of `parent`, building the pointer text only for a message: files
/// hold millions of numbers.
inline double read_number_at(const Source& src, const json& j, const std::string& parent, std::size_t i) {
  if (j.is_number()) {
    const double v = j.get<double>();
    if (std::isfinite(v)) return v;
  }
  return read_number(src, j, child(parent, i));
}

/// An integer in [lo, hi]; 2.0 counts as 2, since some writers emit every number as a double.
inline int read_int(const Source& src, const json& j, const std::string& ptr, int lo, int hi,
             const std::string& expected) {
  if (!j.is_number()) fail_type(src, ptr, j, expected);
  const double v = j.get<double>();
  if (v != std::floor(v) || v < lo || v > hi) fail_type(src, ptr, j, expected);
  return static_cast<int>(v);
}

inline std::string read_string(const Source& src, const json& j, const std::string& ptr,
                        const std::string& expected) {
  if (!j.is_string()) fail_type(src, ptr, j, expected);
  return j.get<std::string>();
}

inline std::vector<double> read_numbers(const Source& src, const json& j, const std::string& ptr,
                                 const std::string& expected) {
  expect_array(src, j, ptr, expected);
  std::vector<double> out;
  out.reserve(j.size());
  for (std::size_t i = 0; i < j.size(); ++i) out.push_back(read_number_at(src, j[i], ptr, i));
  return out;
}

// ------------------------------------------------------------------------------------------
// Splines

/// What each control point holds, for messages: dim 6, "6 (xyz + 3 properties)".
struct PointShape {
  int dim;
  std::string text;
};

inline PointShape point_shape(std::size_t properties) {
  const int dim = 3 + static_cast<int>(properties);
  if (properties == 0) return {dim, "3 (xyz)"};
  const std::string props =
      properties == 1 ? "1 property" : std::to_string(properties) + " properties";
  return {dim, std::to_string(dim) + " (xyz + " + props + ")"};
}

template <int P>
inline std::array<int, P> read_orders(const Source& src, const json& j, const std::string& ptr) {
  const std::string what = std::to_string(P) + " orders (degree + 1), one per direction";
  expect_array(src, j, ptr, what);
  if (j.size() != P)
    src.fail(ptr, plural(static_cast<std::int64_t>(j.size()), "order") + "; expected " + what);
  std::array<int, P> orders{};
  for (int d = 0; d < P; ++d)
    orders[d] = read_int(src, j[d], child(ptr, d), 1, INT_MAX,
                         "an integer order (degree + 1) of at least 1");
  return orders;
}

inline KnotVector read_knot_vector(const Source& src, const json& j, const std::string& ptr, int order) {
  std::vector<double> knots = read_numbers(src, j, ptr, "an array of knots");
  for (std::size_t i = 1; i < knots.size(); ++i)
    if (knots[i] < knots[i - 1])
      src.fail(child(ptr, i), "knot " + format_double(knots[i]) + " is less than knot " +
                                  std::to_string(i - 1) + " (" + format_double(knots[i - 1]) +
                                  "); expected non-decreasing knots");
  // Checked here, in 64 bits, so that KnotVector never computes 2 * order from a huge order.
  const auto needed = 2 * static_cast<std::int64_t>(order);
  if (static_cast<std::int64_t>(knots.size()) < needed)
    src.fail(ptr, plural(static_cast<std::int64_t>(knots.size()), "knot") + " for order " +
                      std::to_string(order) + "; expected at least " + std::to_string(needed) +
                      " (control points + order, with at least order control points)");
  try {
    return KnotVector(order, std::move(knots));
  } catch (const Error& e) {
    throw e.within(src.at(ptr));
  }
}

/// Product of the counts, saturating: absurd counts must give a message, not an overflow.
inline std::int64_t saturating_product(std::int64_t a, std::int64_t b) {
  return (b != 0 && a > INT64_MAX / b) ? INT64_MAX : a * b;
}

inline std::vector<double> read_points(const Source& src, const json& j, const std::string& ptr,
                                std::int64_t count, const std::string& count_text,
                                const PointShape& shape) {
  const std::string row_what = "a control point: an array of " + shape.text + " numbers";
  expect_array(src, j, ptr, "an array of control points, each " + row_what);
  if (static_cast<std::int64_t>(j.size()) != count)
    src.fail(ptr, plural(static_cast<std::int64_t>(j.size()), "control point") + "; expected " +
                      count_text);
  std::vector<double> out;
  out.reserve(j.size() * static_cast<std::size_t>(shape.dim));
  for (std::size_t i = 0; i < j.size(); ++i) {
    const json& row = j[i];
    if (!row.is_array()) fail_type(src, child(ptr, i), row, row_what);
    if (row.size() != static_cast<std::size_t>(shape.dim))
      src.fail(child(ptr, i), plural(static_cast<std::int64_t>(row.size()), "coordinate") +
                                  "; expected " + shape.text);
    for (std::size_t k = 0; k < row.size(); ++k) {
      if (row[k].is_number() && std::isfinite(row[k].get<double>()))
        out.push_back(row[k].get<double>());
      else
        read_number(src, row[k], child(child(ptr, i), k));  // throws with the pointer
    }
  }
  return out;
}

inline std::vector<double> read_weights(const Source& src, const json* j, const std::string& ptr,
                                 std::int64_t count) {
  if (j == nullptr || j->is_null()) return {};
  std::vector<double> w = read_numbers(src, *j, ptr, "null or an array of positive weights");
  if (static_cast<std::int64_t>(w.size()) != count)
    src.fail(ptr, plural(static_cast<std::int64_t>(w.size()), "weight") + "; expected " +
                      std::to_string(count) + " (one per control point) or null");
  for (std::size_t i = 0; i < w.size(); ++i)
    if (!(w[i] > 0))
      src.fail(child(ptr, i), "weight " + format_double(w[i]) + "; expected a positive weight");
  return w;
}

template <int P>
spline::TensorSpline<P> read_spline(const Source& src, const json& j, const std::string& ptr,
                                    const PointShape& shape) {
  const char* kind = P == 3 ? "a trivariate" : P == 2 ? "a surface" : "a curve";
  const std::string what = std::string(kind) + " {\"orders\", \"knots\", \"points\", \"weights\"}";
  expect_object(src, j, ptr, what);
  const auto orders =
      read_orders<P>(src, require(src, j, ptr, "orders", what), child(ptr, "orders"));
  const std::string kp = child(ptr, "knots");
  const json& kj = expect_array(src, require(src, j, ptr, "knots", what), kp,
                                std::to_string(P) + " knot vectors, one per direction");
  if (kj.size() != P)
    src.fail(kp, plural(static_cast<std::int64_t>(kj.size()), "knot vector") + "; expected " +
                     std::to_string(P) + ", one per direction");
  std::array<KnotVector, P> knots;
  std::int64_t count = 1;
  std::string counts_text;
  for (int d = 0; d < P; ++d) {
    knots[d] = read_knot_vector(src, kj[d], child(kp, d), orders[d]);
    count = saturating_product(count, knots[d].size());
    counts_text += (d ? " x " : "") + std::to_string(knots[d].size());
  }
  const std::string count_text =
      std::to_string(count) + " (" + counts_text + ", from the knot vectors and orders)";
  auto points = read_points(src, require(src, j, ptr, "points", what), child(ptr, "points"), count,
                            count_text, shape);
  auto weights = read_weights(src, find(j, "weights"), child(ptr, "weights"), count);
  try {
    return spline::TensorSpline<P>(std::move(knots), shape.dim, std::move(points),
                                   std::move(weights));
  } catch (const Error& e) {
    throw e.within(src.at(ptr));
  }
}

// ------------------------------------------------------------------------------------------
// The header shared by models and scenes: version, units, property names, cell names

/// The model format version (model_json.hpp), required at /trivox.
inline void check_version(const Source& src, const json& root) {
  const json& v = require(src, root, "", "trivox",
                          "\"trivox\": 1 (the model format version) in a trivox model file");
  if (!v.is_number()) fail_type(src, "/trivox", v, "the format version 1");
  if (v != model_format_version)
    src.fail("/trivox", "format version " + v.dump() +
                            "; expected 1 (this trivox reads model format version 1)");
}

inline std::string read_units(const Source& src, const json& root) {
  const json* j = find(root, "units");
  if (j == nullptr) return "mm";
  const std::string what = "one of \"um\", \"mm\", \"cm\", \"m\", \"in\"";
  const std::string units = read_string(src, *j, "/units", what);
  if (!known_units(units))
    src.fail("/units", "unknown units " + quote(units) + "; expected " + what);
  return units;
}

inline std::vector<std::string> read_properties(const Source& src, const json& root) {
  const json* j = find(root, "properties");
  if (j == nullptr || j->is_null()) return {};
  const std::string what = "a unique non-empty property name";
  expect_array(src, *j, "/properties", "an array of property names");
  std::vector<std::string> out;
  for (std::size_t i = 0; i < j->size(); ++i) {
    const std::string p = child("/properties", i);
    std::string name = read_string(src, (*j)[i], p, what);
    if (name.empty()) src.fail(p, "empty name; expected " + what);
    for (std::size_t k = 0; k < out.size(); ++k)
      if (out[k] == name)
        src.fail(p,
                 quote(name) + " repeats /properties/" + std::to_string(k) + "; expected " + what);
    out.push_back(std::move(name));
  }
  return out;
}

/// Names taken so far (cells and surfaces share one namespace), with their owner's pointer.
using NameTable = std::map<std::string, std::string>;

inline std::string read_name(const Source& src, const json& obj, const std::string& ptr,
                      NameTable& names) {
  const std::string what = "a unique non-empty name";
  const std::string np = child(ptr, "name");
  std::string name = read_string(src, require(src, obj, ptr, "name", what), np, what);
  if (name.empty()) src.fail(np, "empty name; expected " + what);
  const auto [it, fresh] = names.emplace(name, ptr);
  if (!fresh)
    src.fail(np, quote(name) + " is also the name of " + it->second + "; expected " + what);
  return name;
}

// ------------------------------------------------------------------------------------------
// Writing

inline void write_numbers(std::string& out, std::span<const double> values) {
  out += '[';
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i) out += ", ";
    out += format_double(values[i]);
  }
  out += ']';
}

/// A spline object at the given indentation, one knot vector and one control point per line,
/// weights one u-row per line.
template <int P>
inline void write_spline(std::string& out, const spline::TensorSpline<P>& s, const std::string& indent) {
  const std::string in1 = indent + "  ", in2 = indent + "    ";
  out += "{\n" + in1 + "\"orders\": [";
  for (int d = 0; d < P; ++d) out += (d ? ", " : "") + std::to_string(s.knots(d).order());
  out += "],\n" + in1 + "\"knots\": [";
  for (int d = 0; d < P; ++d) {
    out += (d ? ",\n" : "\n") + in2;
    write_numbers(out, s.knots(d).knots());
  }
  out += "\n" + in1 + "],\n" + in1 + "\"points\": [";
  for (int r = 0; r < s.size(); ++r) {
    out += (r ? ",\n" : "\n") + in2;
    write_numbers(out, s.point(r));
  }
  out += "\n" + in1 + "],\n" + in1 + "\"weights\": ";
  if (!s.rational()) {
    out += "null";
  } else {
    const auto row = static_cast<std::size_t>(s.count(0));
    const std::span<const double> w = s.weights();
    out += '[';
    for (std::size_t i = 0; i < w.size(); ++i)
      out += (i == 0 ? "\n" + in2 : i % row == 0 ? ",\n" + in2 : ", ") + format_double(w[i]);
    out += "\n" + in1 + "]";
  }
  out += "\n" + indent + "}";
}

}  // namespace trivox::io::json_io
