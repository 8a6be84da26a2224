// `trivox slice`: being written (issue 3).
#include "common.hpp"

namespace trivox::cli {
void add_slice(CLI::App&, Common&) {}
}  // namespace trivox::cli
