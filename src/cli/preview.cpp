// `trivox preview`: being written (issue 3).
#include "common.hpp"

namespace trivox::cli {
void add_preview(CLI::App&, Common&) {}
}  // namespace trivox::cli
