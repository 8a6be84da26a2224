// Streaming a slice PNG row by row, the chunk check that precedes decoding, and finding the slice
// files of a stack folder (png_rows.hpp). Decoding is the PNG module's (png_codec.hpp).
#include "png_rows.hpp"

#include <algorithm>
#include <array>
#include <vector>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <sstream>

#include "png_codec.hpp"
#include "trivox/error.hpp"

namespace trivox::io {

namespace fs = std::filesystem;

namespace detail {

std::string rgba_text(const std::uint8_t* p) {
  return std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + " " + std::to_string(p[3]);
}

std::map<long long, std::string> list_slices(const fs::path& dir, const std::string& prefix) {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    std::string name = it->path().filename().string();
    if (name.size() <= prefix.size() + 4 || !name.starts_with(prefix) || !name.ends_with(".png")) continue;
    const std::string_view digits = std::string_view(name).substr(prefix.size(), name.size() - prefix.size() - 4);
    if (digits.size() > 18 || !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
      continue;
    std::error_code fe;
    if (!it->is_regular_file(fe)) continue;
    names.push_back(std::move(name));
  }
  std::sort(names.begin(), names.end());
  std::map<long long, std::string> out;
  for (auto& name : names) {
    const std::string_view digits = std::string_view(name).substr(prefix.size(), name.size() - prefix.size() - 4);
    long long n = 0;
    std::from_chars(digits.data(), digits.data() + digits.size(), n);
    out.emplace(n, std::move(name));
  }
  return out;
}

// ------------------------------------------------------------------------------------------------
// Row reader

struct PngRowReader::Impl {
  std::string bytes;                 // the whole file: checked, then decoded from memory
  std::unique_ptr<PngDecoder> in;    // reads `bytes`: declared after it, destroyed before it
  std::vector<std::uint8_t> native;  // chunk rows as stored (3 or 4 channels)
  std::vector<std::uint8_t> rgba;    // chunk rows expanded to RGBA (3-channel files only)
  int rows_per_chunk = 1;
  int begin = 0, end = 0;            // rows held
};

static std::uint32_t crc32_png(const char* data, std::size_t n, std::uint32_t crc) {
  static const auto table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  for (std::size_t i = 0; i < n; ++i) crc = table[(crc ^ static_cast<unsigned char>(data[i])) & 0xFF] ^ (crc >> 8);
  return crc;
}

/// Walks the chunk list (lengths, CRCs, IHDR first, IEND last) before libpng sees the file:
/// truncated or damaged files are reported here, with where they break, and libpng (which
/// prints its own errors on stderr) only decodes files that are whole.
std::string png_structure_problem(std::string_view b) {
  static const char signature[] = "\x89PNG\r\n\x1a\n";
  if (b.size() < 8 || b.compare(0, 8, signature, 8) != 0)
    return b.empty() ? "empty file; expected a PNG" : "not a PNG (no PNG signature); expected a PNG file";
  std::size_t at = 8;
  bool first = true;
  while (true) {
    if (at + 8 > b.size())
      return "truncated: the file ends at byte " + std::to_string(b.size()) + " without an IEND chunk; expected a complete PNG file";
    const auto u = [&](std::size_t k) { return static_cast<std::uint32_t>(static_cast<unsigned char>(b[k])); };
    const std::uint64_t length = u(at) << 24 | u(at + 1) << 16 | u(at + 2) << 8 | u(at + 3);
    const std::string type(b.substr(at + 4, 4));
    if (at + 12 + length > b.size())
      return "truncated: chunk " + type + " at byte " + std::to_string(at) + " needs " + std::to_string(length + 12) +
             " bytes, the file ends at byte " + std::to_string(b.size()) + "; expected a complete PNG file";
    if (first && type != "IHDR") return "first chunk " + type + "; expected IHDR (a damaged PNG)";
    first = false;
    const std::size_t data = at + 8, crc_at = data + static_cast<std::size_t>(length);
    const std::uint32_t stored = u(crc_at) << 24 | u(crc_at + 1) << 16 | u(crc_at + 2) << 8 | u(crc_at + 3);
    const std::uint32_t crc = crc32_png(b.data() + at + 4, 4 + static_cast<std::size_t>(length), 0xFFFFFFFFu) ^ 0xFFFFFFFFu;
    if (crc != stored)
      return "chunk " + type + " at byte " + std::to_string(at) + " fails its CRC; expected an undamaged PNG file";
    at = crc_at + 4;
    if (type == "IEND") return {};
  }
}

PngRowReader::PngRowReader(const fs::path& path) : impl_(std::make_unique<Impl>()) {
  {
    std::ifstream f(path, std::ios::binary);
    if (!f) {
      error_ = std::string("cannot open: ") + std::strerror(errno);
      return;
    }
    std::ostringstream s;
    s << f.rdbuf();
    impl_->bytes = std::move(s).str();
  }
  error_ = png_structure_problem(impl_->bytes);
  if (!error_.empty()) return;
  std::string why;
  impl_->in = png_codec().decoder(impl_->bytes.data(), impl_->bytes.size(), path.string(), why);
  if (!impl_->in) {
    error_ = "unreadable PNG: " + (why.empty() ? std::string("cannot open") : why) + "; expected a complete PNG file";
    return;
  }
  const PngSpec& spec = impl_->in->spec();
  width_ = spec.width;
  height_ = spec.height;
  channels_ = spec.channels;
  bits_ = spec.bits;
  if (width_ <= 0 || height_ <= 0) error_ = "an empty image; expected a slice";
  // About 1 MB of rows per read: few calls into OpenImageIO, little memory.
  impl_->rows_per_chunk = std::clamp<int>(static_cast<int>((1 << 20) / (std::max(width_, 1) * 4LL)), 1, 256);
}

PngRowReader::~PngRowReader() = default;  // the decoder closes the file

std::string PngRowReader::format_problem() const {
  if (bits_ != 8 || (channels_ != 3 && channels_ != 4))
    return std::to_string(bits_) + "-bit, " + std::to_string(channels_) + " channel" + (channels_ == 1 ? "" : "s") +
           "; expected 8-bit RGBA (or RGB)";
  return {};
}

const std::uint8_t* PngRowReader::row(int y) {
  if (!ok() || y < 0 || y >= height_) return nullptr;
  Impl& m = *impl_;
  const std::size_t w = static_cast<std::size_t>(width_);
  if (y < m.begin || y >= m.end) {
    if (y < m.begin) {
      error_ = "rows requested out of order";
      return nullptr;
    }
    m.begin = y;
    m.end = std::min(height_, y + m.rows_per_chunk);
    const int nc = std::min(channels_, 4);
    m.native.resize(w * static_cast<std::size_t>(m.end - m.begin) * static_cast<std::size_t>(nc));
    if (!m.in->rows(m.begin, m.end, nc, m.native.data())) {
      const std::string why = m.in->error();
      error_ = "corrupt PNG data (rows " + std::to_string(m.begin) + ".." + std::to_string(m.end - 1) + " of " +
               std::to_string(height_) + "): " + (why.empty() ? std::string("cannot decode") : why) +
               "; expected a complete PNG file";
      m.begin = m.end = 0;
      return nullptr;
    }
    if (nc == 3) {
      const std::size_t n = w * static_cast<std::size_t>(m.end - m.begin);
      m.rgba.resize(n * 4);
      for (std::size_t k = 0; k < n; ++k) {
        m.rgba[4 * k] = m.native[3 * k];
        m.rgba[4 * k + 1] = m.native[3 * k + 1];
        m.rgba[4 * k + 2] = m.native[3 * k + 2];
        m.rgba[4 * k + 3] = 255;
      }
    }
  }
  const std::uint8_t* base = channels_ == 3 ? m.rgba.data() : m.native.data();
  return base + static_cast<std::size_t>(y - m.begin) * w * 4;
}

}  // namespace detail

}  // namespace trivox::io
