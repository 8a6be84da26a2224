// `trivox locate`: being written (issue 3).
#include "common.hpp"

namespace trivox::cli {
void add_locate(CLI::App&, Common&) {}
}  // namespace trivox::cli
