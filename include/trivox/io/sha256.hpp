/// @file trivox/io/sha256.hpp
/// @brief SHA-256 digests (FIPS 180-4) of bytes and files, as lowercase hex: what manifests and
/// the VDB metadata record to identify inputs and outputs.
///
/// OpenSSL's EVP interface (libcrypto) does the hashing. Cost: one pass over the bytes (about
/// 0.5 to 2 GB/s per core); sha256_file streams the file in 1 MiB blocks, so memory stays
/// constant whatever the file size.
#pragma once
#include <filesystem>
#include <string>
#include <string_view>

namespace trivox::io {

/// The SHA-256 digest of `bytes`: 64 lowercase hex digits.
/// @throws Error (failed) only if libcrypto itself fails
std::string sha256_hex(std::string_view bytes);

/// The SHA-256 digest of the file's content: 64 lowercase hex digits.
/// @throws Error (bad_input) "<path>: <reason>; expected a readable file" when the file is
///         missing, a folder or unreadable
std::string sha256_file(const std::filesystem::path& path);

}  // namespace trivox::io
