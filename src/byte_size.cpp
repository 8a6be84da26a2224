#include "trivox/byte_size.hpp"

#include <cstdio>

namespace trivox {

namespace {

std::string scaled(double b, double step, const char* const* units, int count) {
  int u = 0;
  while (b >= step && u < count - 1) b /= step, ++u;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g %s", b, units[u]);
  return buf;
}

}  // namespace

std::string file_size_text(double bytes) {
  static const char* const units[] = {"B", "KB", "MB", "GB", "TB", "PB"};
  return scaled(bytes, 1000.0, units, 6);
}

std::string memory_size_text(double bytes) {
  static const char* const units[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB"};
  return scaled(bytes, 1024.0, units, 6);
}

}  // namespace trivox
