#include "common.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include "trivox/error.hpp"
#include "trivox/limits.hpp"

namespace trivox::cli {

void add_limit_option(CLI::App& app) {
  std::string names;
  for (const auto& l : limit_table()) names += (names.empty() ? "" : ", ") + std::string(l.name);
  app.add_option_function<std::vector<std::string>>(
         "--limit",
         [](const std::vector<std::string>& items) {
           Limits limits = default_limits();
           for (const auto& item : items) set_limit(limits, item, "--limit");
           set_default_limits(limits);
         },
         "Set an input limit, repeatable (docs/limits.md): " + names)
      ->type_name("NAME=N")
      ->allow_extra_args(false)  // one NAME=N per --limit: the model's name is no limit
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
}

void apply_limits_environment() {
  const char* env = std::getenv("TRIVOX_LIMITS");
  if (env == nullptr || *env == '\0') return;
  Limits limits = default_limits();
  set_limits(limits, env, "TRIVOX_LIMITS");
  set_default_limits(limits);
}

std::vector<double> parse_numbers(const std::string& text, std::size_t count, const std::string& option) {
  std::vector<double> out;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t comma = text.find(',', pos);
    const std::string item = text.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || end == item.c_str() || *end != '\0' || !std::isfinite(v))
      throw Error(option + " " + text + ": \"" + item + "\" is not a finite number; expected " +
                  std::to_string(count) + " comma-separated numbers");
    out.push_back(v);
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  if (out.size() != count)
    throw Error(option + " " + text + ": " + std::to_string(out.size()) + " numbers; expected " + std::to_string(count) +
                " comma-separated numbers");
  return out;
}

// Strings from files (names and metadata of a damaged VDB, say) may hold invalid UTF-8: replaced
// by U+FFFD rather than refused, so the JSON always prints.
void print_json(const nlohmann::ordered_json& value) {
  std::cout << value.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << '\n';
}

std::string fmt(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

}  // namespace trivox::cli
