// The trivox executable: a thin command line over the library. Exit codes (docs/architecture.md): 0 success,
// 1 the operation failed on valid input, 2 bad usage or bad input. Every exception is caught
// here, so no input ends in a crash.
#include <cstdio>
#include <exception>
#include <new>
#include <string>

#include "common.hpp"
#include "trivox/error.hpp"
#include "trivox/version.hpp"

namespace {

/// CLI11's parse errors in trivox's words (docs/architecture.md: the place, what was found, what was
/// expected): "--layer abc: not a number; expected a number: <the option's help>".
std::string usage_message(const CLI::App& app, const CLI::ParseError& e, const char* first_arg) {
  const auto subs = app.get_subcommands();
  const CLI::App* sub = subs.empty() ? nullptr : subs.front();
  if (!sub && first_arg && first_arg[0] != '-') {
    std::string names;
    for (const CLI::App* s : app.get_subcommands({})) names += (names.empty() ? "" : ", ") + s->get_name();
    return std::string(first_arg) + ": unknown command; expected one of " + names + " (trivox --help)";
  }
  const std::string help = sub ? "trivox " + sub->get_name() + " --help" : std::string("trivox --help");
  std::string what = e.what();
  static const std::string convert = "Could not convert: ";
  if (dynamic_cast<const CLI::ConversionError*>(&e) && what.starts_with(convert)) {
    const std::size_t eq = what.find(" = ", convert.size());
    if (eq != std::string::npos) {
      const std::string name = what.substr(convert.size(), eq - convert.size()), value = what.substr(eq + 3);
      const CLI::Option* o = sub ? sub->get_option_no_throw(name) : nullptr;
      const std::string type = o ? o->get_type_name() : std::string();
      const char* kind = type == "FLOAT" ? "a number" : type == "INT" ? "a whole number" : type == "UINT" ? "a whole number, 0 or more" : nullptr;
      if (kind)
        return name + " " + value + ": not " + kind + "; expected " + kind +
               (o->get_description().empty() ? std::string() : " (" + o->get_description() + ")");
    }
  }
  if (!what.empty() && what.back() == '.') what.pop_back();
  return what + "; see " + help;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"trivox: heterogeneous B-spline volumes (V-models) to printable voxels", "trivox"};
  app.set_version_flag("--version", std::string("trivox ") + trivox::version);
  app.require_subcommand(1);
  app.fallthrough();
  trivox::cli::Common common;
  trivox::cli::add_info(app, common);
  trivox::cli::add_eval(app, common);
  trivox::cli::add_locate(app, common);
  trivox::cli::add_slice(app, common);
  trivox::cli::add_inspect(app, common);
  trivox::cli::add_preview(app, common);
  trivox::cli::add_render(app, common);
  trivox::cli::add_merge(app, common);
  trivox::cli::add_validate(app, common);
  trivox::cli::add_build(app, common);
  trivox::cli::add_construct(app, common);
  trivox::cli::add_mesh(app, common);
  trivox::cli::add_limit_option(app);
  try {
    trivox::cli::apply_limits_environment();
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "trivox: error: %s\n", usage_message(app, e, argc > 1 ? argv[1] : nullptr).c_str());
    return 2;
  } catch (const trivox::Error& e) {
    std::fprintf(stderr, "trivox: error: %s\n", e.what());
    return e.kind() == trivox::ErrorKind::bad_input ? 2 : 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "trivox: error: out of memory\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "trivox: error: %s\n", e.what());
    return 1;
  }
  return common.exit_code;
}
