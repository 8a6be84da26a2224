/// @file src/detail/json_text.hpp
/// @brief Private to trivox_core: how JSON values are named in error messages, shared by every
/// JSON reader (model files in io, palettes in slice) so messages read alike.
#pragma once
#include <nlohmann/json.hpp>
#include <string>

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

}  // namespace trivox::detail
