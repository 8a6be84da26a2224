/// @file src/detail/json_text.hpp
/// @brief Private to trivox_core: how JSON text is parsed and its values named in error messages,
/// shared by every JSON reader (model files and manifests in io, palettes in slice) so messages
/// read alike.
#pragma once
#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "trivox/error.hpp"

namespace trivox::detail {

/// A JSON string literal, ASCII only so that a message never carries broken UTF-8.
inline std::string json_quote(const std::string& s) {
  return nlohmann::json(s).dump(-1, ' ', true, nlohmann::json::error_handler_t::replace);
}

/// What a value is, for "found ...; expected ..." messages.
inline std::string json_describe(const nlohmann::json& j) {
  using nlohmann::json;
  switch (j.type()) {
    case json::value_t::null: return "null";
    case json::value_t::boolean: return j.get<bool>() ? "true" : "false";
    case json::value_t::string: {
      std::string s = json_quote(j.get<std::string>());
      if (s.size() > 40) s = s.substr(0, 36) + "...\"";
      return "the string " + s;
    }
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float: return "the number " + j.dump();
    case json::value_t::array: return "an array of " + std::to_string(j.size());
    case json::value_t::object: return "an object";
    default: return "a binary value";
  }
}

/// "line L, column C" of the character a parser read last before failing (`position` counts the
/// characters read, so the culprit is at position - 1).
inline std::string json_line_column(std::string_view text, std::size_t position) {
  const std::size_t at = std::min(position > 0 ? position - 1 : 0, text.size());
  std::size_t line = 1, line_start = 0;
  for (std::size_t i = 0; i < at; ++i)
    if (text[i] == '\n') ++line, line_start = i + 1;
  return "line " + std::to_string(line) + ", column " + std::to_string(at - line_start + 1);
}

/// nlohmann's parse-error message without its "[json.exception...] parse error at line L,
/// column C: " prefix (callers give their own position), its "last read: '<token>'" kept short
/// and ASCII (an unterminated string would otherwise put the rest of the file, with any invalid
/// bytes, into the message), ending with what was expected.
inline std::string json_parse_message(std::string what) {
  const std::string open = "last read: '";
  if (const auto begin = what.find(open); begin != std::string::npos) {
    const auto from = begin + open.size();
    auto to = what.rfind("'; expected");
    if (to == std::string::npos || to < from) to = what.rfind('\'');
    if (to != std::string::npos && to >= from) {
      std::string token = what.substr(from, to - from);
      if (token.size() > 40) token = "..." + token.substr(token.size() - 37);
      for (char& c : token)
        if (static_cast<unsigned char>(c) >= 0x7f || static_cast<unsigned char>(c) < 0x20) c = '?';
      what = what.substr(0, from) + token + what.substr(to);
    }
  }
  if (what.starts_with("[json.exception."))
    if (const auto p = what.find("] "); p != std::string::npos) what.erase(0, p + 2);
  if (what.starts_with("parse error"))
    if (const auto p = what.find(": "); p != std::string::npos) what.erase(0, p + 2);
  if (what.find("number overflow") != std::string::npos)
    return what + "; expected a finite number (magnitude below 1.8e308)";
  if (what.find("expected") == std::string::npos) what += "; expected well-formed JSON";
  return what;
}

/// Parses JSON text into a DOM, or throws trivox::Error (bad_input) "<source>: line L, column C:
/// malformed JSON: ...; expected ...".
inline nlohmann::json parse_json_text(std::string_view text, const std::string& source) {
  using nlohmann::json;
  try {
    return json::parse(text.begin(), text.end());
  } catch (const json::parse_error& e) {
    throw Error(source + ": " + json_line_column(text, e.byte) + ": malformed JSON: " + json_parse_message(e.what()));
  } catch (const json::exception& e) {
    // A number overflow (1e999) comes without a position: find the quoted token.
    std::string where;
    const std::string what = e.what();
    if (const auto q = what.find("parsing '"); q != std::string::npos) {
      const auto end = what.find('\'', q + 9);
      const auto at = text.find(what.substr(q + 9, end - (q + 9)));
      if (end != std::string::npos && at != std::string_view::npos) where = json_line_column(text, at + 1) + ": ";
    }
    throw Error(source + ": " + where + "malformed JSON: " + json_parse_message(what));
  }
}

}  // namespace trivox::detail
