// The trivox executable: a thin command line over the library. Exit codes (DESIGN.md): 0 success,
// 1 the operation failed on valid input, 2 bad usage or bad input. Every exception is caught
// here, so no input ends in a crash.
#include <cstdio>
#include <exception>
#include <new>

#include "common.hpp"
#include "trivox/error.hpp"
#include "trivox/version.hpp"

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
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
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
