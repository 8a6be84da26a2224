/// @file trivox/byte_size.hpp
/// @brief Sizes in bytes as people read them: files in decimal units (what `ls -h --si` and
/// disks say), memory in binary units (what `--max-memory 2G` means: 2 GiB).
///
/// Cost: constant.
#pragma once
#include <string>

namespace trivox {

/// "15 MB", "1.61 GB": three significant digits, powers of 1000 (a file's or an output's size).
std::string file_size_text(double bytes);

/// "64 MiB", "1.88 GiB": three significant digits, powers of 1024 (memory, limits).
std::string memory_size_text(double bytes);

}  // namespace trivox
