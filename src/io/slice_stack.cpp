// Voxel Print stacks: PNG encoding and decoding (OpenImageIO, through the module that
// png_codec() loads), ConfigFile.xml (pugixml), the .gcvf zip (libzip), and the row reader that
// inspection and previews share.
#include "trivox/io/slice_stack.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <zip.h>
#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstring>
#include <ctime>
#include <fstream>
#include <functional>
#include <memory>
#include <pugixml.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "png_codec.hpp"
#include "png_rows.hpp"
#include "trivox/error.hpp"
#include "trivox/io/model_file.hpp"

namespace trivox::io {

namespace fs = std::filesystem;

// ------------------------------------------------------------------------------------------------
// Names

std::string StackConfig::slice_name(int i) const {
  const long long n = static_cast<long long>(start_index) + i;
  std::string digits_text = std::to_string(n < 0 ? -n : n);
  if (static_cast<int>(digits_text.size()) < digits)
    digits_text.insert(0, static_cast<std::size_t>(digits) - digits_text.size(), '0');
  return prefix + (n < 0 ? "-" : "") + digits_text + ".png";
}

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

// ------------------------------------------------------------------------------------------------
// PNG

namespace {

/// A PNG encoder into memory with the slices' settings (encode_png_rgba's comment): the module's
/// encoder, its failures turned into trivox::Error.
class SlicePngWriter {
public:
  SlicePngWriter(int width, int height, double dpi_x, double dpi_y, int level) {
    if (width <= 0 || height <= 0)
      throw Error("PNG of " + std::to_string(width) + " x " + std::to_string(height) +
                  " pixels; expected a positive width and height");
    if (level < 0 || level > 9) throw Error("PNG zlib level " + std::to_string(level) + "; expected 0..9");
    detail::PngEncodeSettings settings;
    settings.width = width;
    settings.height = height;
    settings.level = level;
    if (dpi_x > 0 && dpi_y > 0) {
      // pHYs holds whole pixels per metre and OpenImageIO truncates: hand it the rounded value
      // (exact in a float below 2^24, i.e. any dpi up to 400000).
      settings.phys = true;
      settings.pixels_per_metre_x = static_cast<float>(std::round(dpi_x / 0.0254));
      settings.pixels_per_metre_y = static_cast<float>(std::round(dpi_y / 0.0254));
    }
    std::string why;
    out_ = detail::png_codec().encoder(why);
    if (!out_) throw Error("PNG encoder unavailable: " + why, ErrorKind::failed);
    if (!out_->open(settings)) fail();
  }
  /// The whole image, rows top to bottom.
  void image(const std::uint8_t* rgba) {
    if (!out_->image(rgba)) fail();
  }
  /// Rows [y0, y1), in order.
  void rows(int y0, int y1, const std::uint8_t* rgba) {
    if (!out_->rows(y0, y1, rgba)) fail();
  }
  std::string finish() {
    std::string png;
    if (!out_->finish(png)) fail();
    return png;
  }

private:
  [[noreturn]] void fail() {
    std::string why = out_->error();
    throw Error("PNG encoding failed: " + (why.empty() ? std::string("unknown error") : why), ErrorKind::failed);
  }
  std::unique_ptr<detail::PngEncoder> out_;
};

/// rgba[4 j ..] = colours[index[j]] for j < n.
void paint_scalar(const std::uint8_t* index, std::size_t n, const std::array<std::uint32_t, 256>& colours, std::uint8_t* rgba) {
  for (std::size_t j = 0; j < n; ++j) std::memcpy(rgba + 4 * j, &colours[index[j]], 4);
}

#if defined(__x86_64__)
/// paint_scalar eight pixels at a time where their indices are 0..6 or 255 (a palette of up to
/// seven materials, and void): one permute from a table of those eight colours.
[[gnu::target("avx2")]] void paint_avx2(const std::uint8_t* index, std::size_t n, const std::array<std::uint32_t, 256>& colours,
                                        std::uint8_t* rgba) {
  std::int32_t t[8];
  for (int k = 0; k < 7; ++k) t[k] = static_cast<std::int32_t>(colours[static_cast<std::size_t>(k)]);
  t[7] = static_cast<std::int32_t>(colours[255]);
  const __m256i table = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(t));
  const __m256i seven = _mm256_set1_epi32(7), ff = _mm256_set1_epi32(255);
  std::size_t j = 0;
  for (; j + 8 <= n; j += 8) {
    const __m256i b = _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(index + j)));
    const __m256i lane = _mm256_min_epu32(b, seven);
    // An index 7..254 (lane 7 but not void) takes the table of all 256.
    const __m256i other = _mm256_andnot_si256(_mm256_cmpeq_epi32(b, ff), _mm256_cmpeq_epi32(lane, seven));
    if (!_mm256_testz_si256(other, other)) {
      paint_scalar(index + j, 8, colours, rgba + 4 * j);
      continue;
    }
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(rgba + 4 * j), _mm256_permutevar8x32_epi32(table, lane));
  }
  paint_scalar(index + j, n - j, colours, rgba + 4 * j);
}
#endif

void paint(const std::uint8_t* index, std::size_t n, const std::array<std::uint32_t, 256>& colours, std::uint8_t* rgba) {
#if defined(__x86_64__)
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (avx2) return paint_avx2(index, n, colours, rgba);
#endif
  paint_scalar(index, n, colours, rgba);
}

}  // namespace

std::string encode_png_rgba(const std::uint8_t* rgba, int width, int height, double dpi_x, double dpi_y, int level) {
  SlicePngWriter enc(width, height, dpi_x, dpi_y, level);
  enc.image(rgba);
  return enc.finish();
}

std::string encode_png_indexed(const std::uint8_t* index, int width, int height, const std::array<std::uint32_t, 256>& colours,
                               double dpi_x, double dpi_y, int level) {
  SlicePngWriter enc(width, height, dpi_x, dpi_y, level);
  // Strips of rows painted into a buffer that stays in the L1/L2 cache while libpng reads it.
  const auto w = static_cast<std::size_t>(width);
  const int strip = std::max(1, static_cast<int>(32768 / w));
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(std::min(strip, height)) * w * 4);
  for (int y0 = 0; y0 < height; y0 += strip) {
    const int y1 = std::min(height, y0 + strip);
    paint(index + static_cast<std::size_t>(y0) * w, static_cast<std::size_t>(y1 - y0) * w, colours, rgba.data());
    enc.rows(y0, y1, rgba.data());
  }
  return enc.finish();
}

RgbaImage decode_png_rgba(std::string_view bytes, const std::string& source) {
  if (const std::string p = detail::png_structure_problem(bytes); !p.empty()) throw Error(source + ": " + p);
  std::string why;
  const auto in = detail::png_codec().decoder(bytes.data(), bytes.size(), "memory.png", why);
  if (!in) throw Error(source + ": not a readable PNG: " + why + "; expected a complete PNG file");
  const detail::PngSpec& spec = in->spec();
  if (spec.channels != 3 && spec.channels != 4)
    throw Error(source + ": " + std::to_string(spec.channels) + " channels; expected RGB or RGBA");
  RgbaImage img;
  img.width = spec.width;
  img.height = spec.height;
  const std::size_t n = static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height);
  std::vector<std::uint8_t> native(n * static_cast<std::size_t>(spec.channels));
  if (!in->image(spec.channels, native.data()))
    throw Error(source + ": cannot decode: " + in->error() + "; expected a complete PNG file");
  if (spec.channels == 4) {
    img.pixels = std::move(native);
  } else {
    img.pixels.resize(n * 4);
    for (std::size_t k = 0; k < n; ++k) {
      std::memcpy(&img.pixels[4 * k], &native[3 * k], 3);
      img.pixels[4 * k + 3] = 255;
    }
  }
  // OpenImageIO reports pHYs in the unit it names; convert to pixels per inch.
  const std::string& unit = spec.resolution_unit;
  const double xr = spec.x_resolution, yr = spec.y_resolution;
  const double to_inch = unit == "inch" || unit == "in" ? 1.0 : unit == "cm" ? 2.54 : unit == "m" || unit == "meter" ? 0.0254 : 0.0;
  img.dpi_x = xr * to_inch;
  img.dpi_y = yr * to_inch;
  return img;  // the decoder closes the file
}

// ------------------------------------------------------------------------------------------------
// ConfigFile.xml

namespace {

std::string num(double v) {
  char buf[32];
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
}

/// A checked value (check_config) in plain decimal notation, never with an exponent: readers
/// of ConfigFile.xml parse 100000 as an integer but not 1e+05 (a 0.1 mm layer's thickness).
std::string decimal(double v) {
  char buf[400];  // check_config bounds v to (0, 1e9]: 10 digits before the point, 340 at most after
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed);
  if (r.ec != std::errc{}) throw Error("ConfigFile.xml: cannot write the number " + num(v) + " in decimal notation");
  return std::string(buf, r.ptr);
}

std::string in_quotes(std::string_view s) {
  std::string out;
  out.reserve(s.size() + 2);
  out.append(1, '"').append(s).append(1, '"');
  return out;
}

std::string_view trim(std::string_view s) {
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
  while (!s.empty() && space(s.front())) s.remove_prefix(1);
  while (!s.empty() && space(s.back())) s.remove_suffix(1);
  return s;
}

/// The canonical place of each element, for messages about missing ones.
const char* canonical(std::string_view name) {
  static const std::pair<const char*, const char*> places[] = {
      {"Version", "GCVF/Version"},
      {"XDpi", "GCVF/Resolution/XDpi"},
      {"YDpi", "GCVF/Resolution/YDpi"},
      {"SliceThicknessNanoMeter", "GCVF/Resolution/SliceThicknessNanoMeter"},
      {"SliceWidth", "GCVF/SliceDimensions/SliceWidth"},
      {"SliceHeight", "GCVF/SliceDimensions/SliceHeight"},
      {"StartIndex", "GCVF/SliceRange/StartIndex"},
      {"NumberOfSlices", "GCVF/SliceRange/NumberOfSlices"},
      {"BitDepth", "GCVF/BitDepth"},
      {"MaxNumberOfColors", "GCVF/MaxNumberOfColors"},
      {"DataSemantics", "GCVF/DataSemantics"},
      {"CreationMode", "GCVF/CreationMode"},
      {"ImageFilePrefix", "GCVF/ImageFilePrefix"},
      {"MaterialList", "GCVF/MaterialList"},
      {"BackGroundMaterialRGBA", "GCVF/MaterialList/BackGroundMaterialRGBA"},
  };
  for (const auto& [n, p] : places)
    if (name == n) return p;
  return "GCVF";
}

/// The file being read and its places: every message names the file, the element path and line.
struct XmlSource {
  const std::string& name;
  std::string_view text;

  std::size_t line_at(std::size_t offset) const {
    offset = std::min(offset, text.size());
    return 1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(offset), '\n'));
  }
  std::size_t column_at(std::size_t offset) const {
    offset = std::min(offset, text.size());
    const std::size_t nl = text.substr(0, offset).rfind('\n');
    return nl == std::string_view::npos ? offset + 1 : offset - nl;
  }
  /// "file: GCVF/MaterialList/Material[1]/RGBA (line 30)"
  std::string where(pugi::xml_node node) const {
    std::vector<std::string> parts;
    for (pugi::xml_node n = node; n && n.type() == pugi::node_element; n = n.parent()) {
      std::string part = n.name();
      if (part == "Material") {
        int i = 0;
        for (pugi::xml_node s = n.previous_sibling("Material"); s; s = s.previous_sibling("Material")) ++i;
        part += "[" + std::to_string(i) + "]";
      }
      parts.push_back(std::move(part));
    }
    std::string s = name + ": ";
    for (auto it = parts.rbegin(); it != parts.rend(); ++it) s += (it == parts.rbegin() ? "" : "/") + *it;
    if (const auto off = node.offset_debug(); off >= 0)
      s += " (line " + std::to_string(line_at(static_cast<std::size_t>(off))) + ")";
    return s;
  }
  [[noreturn]] void fail(pugi::xml_node node, const std::string& what) const { throw Error(where(node) + ": " + what); }
  [[noreturn]] void missing(pugi::xml_node parent, std::string_view child, const std::string& expected) const {
    if (!parent || parent.parent().type() == pugi::node_document)
      throw Error(name + ": " + canonical(child) + ": missing; expected " + expected);
    throw Error(where(parent) + ": no <" + std::string(child) + ">; expected " + expected);
  }
};

/// First element named `name` below `root` (any depth).
pugi::xml_node find(pugi::xml_node root, const char* name) {
  return root.find_node([name](pugi::xml_node n) { return n.type() == pugi::node_element && std::strcmp(n.name(), name) == 0; });
}

double number_in(const XmlSource& src, pugi::xml_node node, double lo, double hi, const std::string& expected) {
  const std::string_view t = trim(node.text().get());
  double v = 0;
  const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (t.empty() || ec != std::errc() || ptr != t.data() + t.size() || !std::isfinite(v))
    src.fail(node, in_quotes(t) + " is not a number; expected " + expected);
  if (!(v >= lo && v <= hi)) src.fail(node, num(v) + "; expected " + expected);
  return v;
}

long long integer_in(const XmlSource& src, pugi::xml_node node, long long lo, long long hi, const std::string& expected) {
  const std::string_view t = trim(node.text().get());
  long long v = 0;
  const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (t.empty() || ec != std::errc() || ptr != t.data() + t.size())
    src.fail(node, in_quotes(t) + " is not an integer; expected " + expected);
  if (v < lo || v > hi) src.fail(node, std::to_string(v) + "; expected " + expected);
  return v;
}

std::array<std::uint8_t, 4> rgba_in(const XmlSource& src, pugi::xml_node node) {
  const std::string expected = "four integers 0..255 \"r g b a\"";
  std::string_view t = trim(node.text().get());
  std::array<std::uint8_t, 4> out{};
  std::size_t k = 0;
  const std::string_view all = t;
  while (!t.empty()) {
    int v = -1;
    const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (ec != std::errc() || ptr == t.data() || k == 4 || v < 0 || v > 255)
      src.fail(node, in_quotes(all) + "; expected " + expected);
    out[k++] = static_cast<std::uint8_t>(v);
    t = trim(t.substr(static_cast<std::size_t>(ptr - t.data())));
    if (!t.empty() && t.front() == ',') t = trim(t.substr(1));  // "r, g, b, a" reads too
  }
  if (k != 4) src.fail(node, in_quotes(all) + "; expected " + expected);
  return out;
}

/// Ranges every config must respect, written and read alike.
constexpr double max_dpi = 100000;
constexpr double max_thickness_nm = 1e9;
constexpr int max_pixels = 1000000;
// A metre of 1 um layers; a J750 tray is 7407 layers of 27 um. The bound keeps a malformed file
// from making inspect or preview plan billions of slices.
constexpr int max_slices = 1000000;
const std::string slices_expected = "a slice count of 1..1000000 (and StartIndex + NumberOfSlices within 2^31)";
const std::string dpi_expected = "a positive number of pixels per inch, at most 100000";
const std::string thickness_expected = "a positive layer thickness in nanometres, at most 1e9 (1 m)";
const std::string size_expected = "a whole number of pixels, 1..1000000";
const std::string prefix_expected = "a file-name prefix without '/', '\\' or NUL";

bool prefix_ok(std::string_view p) { return p.find_first_of(std::string_view("/\\\0", 3)) == std::string_view::npos && p != ".."; }

/// Checks what the XML cannot express wrongly once parsed, for config_xml's input.
void check_config(const StackConfig& c) {
  const auto bad = [](const std::string& what) { throw Error("ConfigFile.xml: " + what); };
  if (c.version < 1) bad("Version " + std::to_string(c.version) + "; expected a positive format version (2)");
  if (!(c.dpi_x > 0 && c.dpi_x <= max_dpi)) bad("XDpi " + num(c.dpi_x) + "; expected " + dpi_expected);
  if (!(c.dpi_y > 0 && c.dpi_y <= max_dpi)) bad("YDpi " + num(c.dpi_y) + "; expected " + dpi_expected);
  if (!(c.slice_thickness_nm > 0 && c.slice_thickness_nm <= max_thickness_nm))
    bad("SliceThicknessNanoMeter " + num(c.slice_thickness_nm) + "; expected " + thickness_expected);
  if (c.width < 1 || c.width > max_pixels) bad("SliceWidth " + std::to_string(c.width) + "; expected " + size_expected);
  if (c.height < 1 || c.height > max_pixels) bad("SliceHeight " + std::to_string(c.height) + "; expected " + size_expected);
  if (c.start_index < 0) bad("StartIndex " + std::to_string(c.start_index) + "; expected 0 or more");
  if (c.slices < 1 || c.slices > max_slices || static_cast<long long>(c.start_index) + c.slices - 1 > INT_MAX)
    bad("NumberOfSlices " + std::to_string(c.slices) + "; expected " + slices_expected);
  if (!prefix_ok(c.prefix)) bad("ImageFilePrefix " + in_quotes(c.prefix) + "; expected " + prefix_expected);
  std::set<std::array<std::uint8_t, 4>> seen;
  for (std::size_t i = 0; i < c.materials.size(); ++i) {
    const StackMaterial& m = c.materials[i];
    const std::string at = "MaterialList/Material[" + std::to_string(i) + "] " + in_quotes(m.name) + ": ";
    if (m.name.empty()) bad(at + "empty Name; expected the material's name");
    if (m.rgba[3] == 0) bad(at + "RGBA " + detail::rgba_text(m.rgba.data()) + " is transparent; expected alpha > 0 (alpha 0 is void)");
    if (m.rgba == c.background) bad(at + "RGBA " + detail::rgba_text(m.rgba.data()) + " is the background colour; expected a colour of its own");
    if (!seen.insert(m.rgba).second) bad(at + "RGBA " + detail::rgba_text(m.rgba.data()) + " repeats an earlier material's; expected distinct colours");
    if (m.voxel_count < 0) bad(at + "VoxelCount " + std::to_string(m.voxel_count) + "; expected 0 or more");
  }
}

void text_child(pugi::xml_node parent, const char* name, const std::string& value) {
  parent.append_child(name).text().set(value.c_str());
}

}  // namespace

std::string config_xml(const StackConfig& c) {
  check_config(c);
  pugi::xml_document doc;
  pugi::xml_node decl = doc.append_child(pugi::node_declaration);
  decl.append_attribute("version") = "1.0";
  decl.append_attribute("encoding") = "UTF-8";
  doc.append_child(pugi::node_comment).set_value(" GCVF - GrabCAD Voxel Print slice folder, written by trivox ");
  pugi::xml_node root = doc.append_child("GCVF");
  text_child(root, "Version", std::to_string(c.version));
  pugi::xml_node res = root.append_child("Resolution");
  text_child(res, "XDpi", decimal(c.dpi_x));
  text_child(res, "YDpi", decimal(c.dpi_y));
  text_child(res, "SliceThicknessNanoMeter", decimal(c.slice_thickness_nm));
  pugi::xml_node dims = root.append_child("SliceDimensions");
  text_child(dims, "SliceWidth", std::to_string(c.width));
  text_child(dims, "SliceHeight", std::to_string(c.height));
  pugi::xml_node range = root.append_child("SliceRange");
  text_child(range, "StartIndex", std::to_string(c.start_index));
  text_child(range, "NumberOfSlices", std::to_string(c.slices));
  text_child(root, "BitDepth", std::to_string(c.bit_depth));
  text_child(root, "MaxNumberOfColors", std::to_string(c.max_colors));
  text_child(root, "DataSemantics", c.data_semantics);
  text_child(root, "CreationMode", c.creation_mode);
  text_child(root, "ImageFilePrefix", c.prefix);
  pugi::xml_node list = root.append_child("MaterialList");
  text_child(list, "BackGroundMaterialRGBA", detail::rgba_text(c.background.data()));
  for (const StackMaterial& m : c.materials) {
    pugi::xml_node e = list.append_child("Material");
    text_child(e, "Name", m.name);
    text_child(e, "RGBA", detail::rgba_text(m.rgba.data()));
    text_child(e, "VoxelCount", std::to_string(m.voxel_count));
  }
  std::ostringstream s;
  doc.save(s, "  ", pugi::format_default, pugi::encoding_utf8);
  return std::move(s).str();
}

StackConfig parse_config_xml(std::string_view text, const std::string& source) {
  const XmlSource src{source, text};
  pugi::xml_document doc;
  const pugi::xml_parse_result r = doc.load_buffer(text.data(), text.size(), pugi::parse_default, pugi::encoding_utf8);
  if (!r) {
    const auto off = static_cast<std::size_t>(std::max<std::ptrdiff_t>(r.offset, 0));
    throw Error(source + ": line " + std::to_string(src.line_at(off)) + ", column " + std::to_string(src.column_at(off)) +
                ": malformed XML: " + r.description() + "; expected a well-formed GCVF ConfigFile.xml");
  }
  const pugi::xml_node root = doc.document_element();
  if (!root) throw Error(source + ": no root element; expected <GCVF> with the stack's configuration");

  const auto required = [&](const char* name, const std::string& expected) {
    const pugi::xml_node n = find(root, name);
    if (!n) src.missing(root, name, "<" + std::string(name) + "> with " + expected);
    return n;
  };
  StackConfig c;
  c.version = static_cast<int>(integer_in(src, required("Version", "the format version"), 1, INT_MAX, "a positive format version (2)"));
  c.dpi_x = number_in(src, required("XDpi", dpi_expected), 1e-300, max_dpi, dpi_expected);
  c.dpi_y = number_in(src, required("YDpi", dpi_expected), 1e-300, max_dpi, dpi_expected);
  c.slice_thickness_nm = number_in(src, required("SliceThicknessNanoMeter", thickness_expected), 1e-300, max_thickness_nm, thickness_expected);
  c.width = static_cast<int>(integer_in(src, required("SliceWidth", size_expected), 1, max_pixels, size_expected));
  c.height = static_cast<int>(integer_in(src, required("SliceHeight", size_expected), 1, max_pixels, size_expected));
  c.start_index = static_cast<int>(integer_in(src, required("StartIndex", "the first slice number"), 0, INT_MAX, "a slice number, 0 or more"));
  const long long most = std::min<long long>(max_slices, static_cast<long long>(INT_MAX) - c.start_index + 1);
  c.slices = static_cast<int>(integer_in(src, required("NumberOfSlices", "the slice count"), 1, most, slices_expected));
  const pugi::xml_node prefix = required("ImageFilePrefix", "the slice file-name prefix");
  c.prefix = trim(prefix.text().get());
  if (!prefix_ok(c.prefix)) src.fail(prefix, in_quotes(c.prefix) + "; expected " + prefix_expected);
  if (const auto n = find(root, "BitDepth")) c.bit_depth = static_cast<int>(integer_in(src, n, 0, 64, "an integer 0..64"));
  if (const auto n = find(root, "MaxNumberOfColors"))
    c.max_colors = static_cast<int>(integer_in(src, n, 0, INT_MAX, "a non-negative integer"));
  if (const auto n = find(root, "DataSemantics")) c.data_semantics = trim(n.text().get());
  if (const auto n = find(root, "CreationMode")) c.creation_mode = trim(n.text().get());

  const pugi::xml_node list = required("MaterialList", "a <Material> per material");
  if (const auto n = find(list, "BackGroundMaterialRGBA")) c.background = rgba_in(src, n);
  std::vector<pugi::xml_node> colour_nodes;
  for (pugi::xml_node m = list.child("Material"); m; m = m.next_sibling("Material")) {
    StackMaterial mat;
    const pugi::xml_node name = m.child("Name");
    if (!name) src.missing(m, "Name", "the material's name");
    mat.name = trim(name.text().get());
    if (mat.name.empty()) src.fail(name, "empty; expected the material's name (e.g. VeroCyan-V)");
    const pugi::xml_node rgba = m.child("RGBA");
    if (!rgba) src.missing(m, "RGBA", "the material's colour in the slices, \"r g b a\"");
    mat.rgba = rgba_in(src, rgba);
    if (mat.rgba[3] == 0) src.fail(rgba, in_quotes(detail::rgba_text(mat.rgba.data())) + " is transparent; expected alpha > 0 (alpha 0 is void)");
    if (mat.rgba == c.background)
      src.fail(rgba, in_quotes(detail::rgba_text(mat.rgba.data())) + " is the background (void) colour; expected a colour of its own");
    for (std::size_t k = 0; k < c.materials.size(); ++k)
      if (c.materials[k].rgba == mat.rgba)
        src.fail(rgba, in_quotes(detail::rgba_text(mat.rgba.data())) + " is also the colour of " + in_quotes(c.materials[k].name) +
                           "; expected distinct colours");
    const pugi::xml_node count = m.child("VoxelCount");
    if (!count) src.missing(m, "VoxelCount", "the material's voxel count");
    mat.voxel_count = integer_in(src, count, 0, LLONG_MAX, "a voxel count, 0 or more");
    c.materials.push_back(std::move(mat));
  }
  return c;
}

namespace {

[[noreturn]] void no_stack(const fs::path& dir, const std::string& what) {
  throw Error(dir.string() + ": " + what + "; expected a slice folder holding ConfigFile.xml (written by trivox slice)");
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw Error(p.string() + ": cannot open: " + std::strerror(errno) + "; expected a readable file");
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw Error(p.string() + ": cannot read: " + std::strerror(errno) + "; expected a readable file");
  return std::move(s).str();
}

}  // namespace

StackConfig read_stack_config(const fs::path& dir) {
  std::error_code ec;
  const fs::file_status st = fs::status(dir, ec);
  if (!fs::exists(st)) no_stack(dir, "no such folder");
  if (!fs::is_directory(st)) no_stack(dir, "is a file, not a folder");
  const fs::path file = dir / "ConfigFile.xml";
  if (!fs::exists(fs::status(file, ec))) no_stack(dir, "no ConfigFile.xml");
  if (fs::is_directory(file, ec)) no_stack(dir, "ConfigFile.xml is a folder");
  StackConfig c = parse_config_xml(slurp(file), file.string());
  const auto files = detail::list_slices(dir, c.prefix);
  auto first = files.lower_bound(c.start_index);
  if (first == files.end()) first = files.begin();
  if (first != files.end()) c.digits = static_cast<int>(first->second.size() - c.prefix.size() - 4);
  return c;
}

void write_stack_config(const fs::path& dir, const StackConfig& config) {
  write_file_atomically(dir / "ConfigFile.xml", config_xml(config));
}

// ------------------------------------------------------------------------------------------------
// .gcvf

namespace {

/// A zip being written under a temporary name; discarded (and the file removed) unless closed.
class ZipWriter {
public:
  ZipWriter(const fs::path& target, const fs::path& tmp) : target_(target), tmp_(tmp) {
    int err = 0;
    zip_ = zip_open(tmp.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &err);
    if (!zip_) {
      zip_error_t e;
      zip_error_init_with_code(&e, err);
      const std::string why = zip_error_strerror(&e);
      zip_error_fini(&e);
      throw Error(target.string() + ": cannot create: " + why + "; expected a writable path");
    }
  }
  ~ZipWriter() {
    if (zip_) zip_discard(zip_);
    std::error_code ec;
    if (!done_) fs::remove(tmp_, ec);
  }
  ZipWriter(const ZipWriter&) = delete;
  ZipWriter& operator=(const ZipWriter&) = delete;

  void add_file(const fs::path& file, const std::string& name, bool deflate, std::time_t mtime) {
    zip_source_t* s = zip_source_file(zip_, file.c_str(), 0, -1);
    if (!s) fail("cannot read " + file.string());
    const zip_int64_t idx = zip_file_add(zip_, name.c_str(), s, ZIP_FL_ENC_UTF_8);
    if (idx < 0) {
      zip_source_free(s);
      fail("cannot add " + name);
    }
    const auto i = static_cast<zip_uint64_t>(idx);
    if (zip_set_file_compression(zip_, i, deflate ? ZIP_CM_DEFLATE : ZIP_CM_STORE, 0) != 0 ||
        zip_file_set_mtime(zip_, i, mtime, 0) != 0 ||
        zip_file_set_external_attributes(zip_, i, 0, ZIP_OPSYS_UNIX, 0100644u << 16) != 0)
      fail("cannot set the attributes of " + name);
  }

  void close() {
    if (zip_close(zip_) != 0) fail("cannot write");
    zip_ = nullptr;
    // zip_close wrote and renamed its own temporary into tmp_; make it durable, then publish it.
    const int fd = ::open(tmp_.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0 || ::fsync(fd) != 0) {
      const int err = errno;
      if (fd >= 0) ::close(fd);
      throw Error(target_.string() + ": cannot write: " + std::strerror(err) + "; expected a writable path");
    }
    ::close(fd);
    if (::rename(tmp_.c_str(), target_.c_str()) != 0)
      throw Error(target_.string() + ": cannot write: " + std::strerror(errno) + "; expected a writable path");
    done_ = true;
    const fs::path folder = target_.parent_path().empty() ? fs::path(".") : target_.parent_path();
    if (const int dfd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC); dfd >= 0) {
      ::fsync(dfd);
      ::close(dfd);
    }
  }

private:
  [[noreturn]] void fail(const std::string& what) {
    const std::string why = zip_ ? zip_strerror(zip_) : "";
    const bool io = zip_ && zip_error_code_system(zip_get_error(zip_)) != 0;
    throw Error(target_.string() + ": " + what + ": " + why + (io ? "; expected a writable path" : ""),
                io ? ErrorKind::bad_input : ErrorKind::failed);
  }

  fs::path target_, tmp_;
  zip_t* zip_ = nullptr;
  bool done_ = false;
};

/// 1980-01-01 00:00 local time: libzip stores local DOS times, so this reads back as the DOS
/// epoch in every time zone, and archives of the same stack are byte-identical.
std::time_t dos_epoch() {
  std::tm t{};
  t.tm_year = 80;
  t.tm_mon = 0;
  t.tm_mday = 1;
  t.tm_hour = 12;  // noon first, to dodge a DST gap at midnight; then back to 00:00
  t.tm_isdst = -1;
  std::time_t noon = std::mktime(&t);
  return noon - 12 * 3600;
}

}  // namespace

fs::path gcvf_path(const fs::path& dir) {
  fs::path zip = dir;
  if (!zip.has_filename()) zip = zip.parent_path();
  zip += ".gcvf";
  return zip;
}

void zip_stack(const fs::path& dir, const fs::path& gcvf) {
  const StackConfig c = read_stack_config(dir);
  const auto files = detail::list_slices(dir, c.prefix);
  std::vector<std::string> names;
  names.reserve(static_cast<std::size_t>(c.slices));
  for (int i = 0; i < c.slices; ++i) {
    const auto it = files.find(static_cast<long long>(c.start_index) + i);
    if (it == files.end())
      throw Error((dir / c.slice_name(i)).string() + ": missing; expected all " + std::to_string(c.slices) +
                  " slices that ConfigFile.xml lists before packing a .gcvf");
    names.push_back(it->second);
  }
  std::error_code ec;
  if (fs::is_directory(gcvf, ec)) throw Error(gcvf.string() + ": is a folder; expected a .gcvf file path to write");
  std::ostringstream tmp_name;
  tmp_name << "." << gcvf.filename().string() << ".tmp-" << ::getpid() << "-" << std::hex
           << (std::hash<std::thread::id>{}(std::this_thread::get_id()) ^
               static_cast<std::size_t>(std::chrono::steady_clock::now().time_since_epoch().count()));
  const fs::path tmp = gcvf.parent_path() / tmp_name.str();
  const std::time_t mtime = dos_epoch();
  ZipWriter zip(gcvf, tmp);
  zip.add_file(dir / "ConfigFile.xml", "ConfigFile.xml", true, mtime);
  for (const auto& name : names) zip.add_file(dir / name, name, false, mtime);
  zip.close();
}

}  // namespace trivox::io
