/// @file src/cli/common.hpp
/// @brief What every subcommand of the `trivox` executable shares: registration, the output
/// mode, and parsing of option values with messages that say what was expected.
#pragma once
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace trivox::cli {

/// Options common to all subcommands.
struct Common {
  bool json = false;  ///< print one JSON object on stdout instead of the human summary
  int exit_code = 0;  ///< what main returns after a successful run (validate: 1 for invalid cells)
};

/// Each subcommand file defines one of these; main.cpp calls them in order.
void add_info(CLI::App& app, Common& common);
void add_eval(CLI::App& app, Common& common);
void add_locate(CLI::App& app, Common& common);
void add_slice(CLI::App& app, Common& common);
void add_inspect(CLI::App& app, Common& common);
void add_preview(CLI::App& app, Common& common);
void add_render(CLI::App& app, Common& common);
void add_merge(CLI::App& app, Common& common);
void add_validate(CLI::App& app, Common& common);
void add_build(CLI::App& app, Common& common);
void add_construct(CLI::App& app, Common& common);
void add_mesh(CLI::App& app, Common& common);

/// Registers the global option `--limit NAME=N` (repeatable; given before or after the command,
/// thanks to fallthrough) on the main app: each sets one input limit (trivox/limits.hpp) in the
/// process's default limits, which every model reader of every command uses. Applied while the
/// command line is parsed, before any command runs. Cost: constant.
/// @throws trivox::Error (bad_input) from the parse for an unknown limit or a malformed value
void add_limit_option(CLI::App& app);

/// Applies the environment variable TRIVOX_LIMITS ("NAME=N,NAME=N", the same names as --limit,
/// which overrides it) to the process's default limits; nothing when it is unset or empty.
/// @throws trivox::Error (bad_input) naming TRIVOX_LIMITS for an unknown limit or a bad value
void apply_limits_environment();

/// Parses "a,b,c" into exactly `count` finite numbers.
/// @param option  the option's name, for the message ("--uvw")
/// @throws trivox::Error (bad_input) naming the option, the offending text and what was expected
std::vector<double> parse_numbers(const std::string& text, std::size_t count, const std::string& option);

/// Prints a JSON value on stdout (one line per value, 2-space indented).
void print_json(const nlohmann::ordered_json& value);

/// "%.10g"-style formatting for human output.
std::string fmt(double v, int digits = 10);

}  // namespace trivox::cli
