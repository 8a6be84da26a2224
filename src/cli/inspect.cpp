// `trivox inspect`: being written (issue 3).
#include "common.hpp"

namespace trivox::cli {
void add_inspect(CLI::App&, Common&) {}
}  // namespace trivox::cli
