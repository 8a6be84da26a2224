// A picture of a slice stack: contact sheet plus vertical cross-section (write_preview in
// preview.hpp). Everything is drawn into one RGBA canvas in memory; the stack is read
// streaming, a slice per task.
#include "trivox/io/preview.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "png_rows.hpp"
#include "trivox/error.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/io/png_image.hpp"
#include "trivox/io/stack_config.hpp"

namespace trivox::io {

namespace fs = std::filesystem;

namespace {

constexpr int margin = 8;        // between panels and around the sheet
constexpr int label_height = 14; // a line of 2x-scaled 3x5 glyphs plus spacing
constexpr std::uint8_t frame = 32;
constexpr int min_section = 48;  // pixels: below this the cross-section is stretched along z
constexpr int max_thumbnails = 1024;
constexpr long long max_height = 32768;

/// An opaque RGBA picture.
struct Canvas {
  int width, height;
  std::vector<std::uint8_t> px;
  Canvas(int w, int h) : width(w), height(h), px(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4) {
    for (std::size_t i = 0; i < px.size(); i += 4) px[i] = px[i + 1] = px[i + 2] = frame, px[i + 3] = 255;
  }
  std::uint8_t* at(int x, int y) {
    return px.data() + (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 4;
  }
  void set(int x, int y, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
    if (x < 0 || y < 0 || x >= width || y >= height) return;
    std::uint8_t* p = at(x, y);
    p[0] = r, p[1] = g, p[2] = b;
  }
};

/// The checkerboard that void shows as: 8-pixel squares of two dark greys, so that white and
/// clear materials (255 and 137 grey in the default palette) stand out from it.
double checker(int x, int y) { return ((x >> 3) + (y >> 3)) & 1 ? 72.0 : 104.0; }

/// Premultiplied mean colour (r, g, b in 0..255 already times alpha/255, and alpha) over the
/// checkerboard at canvas (x, y).
void composite(Canvas& cv, int x, int y, double r, double g, double b, double a) {
  const double bg = checker(x, y) * (1.0 - a / 255.0);
  cv.set(x, y, static_cast<std::uint8_t>(std::lround(std::min(255.0, r + bg))),
         static_cast<std::uint8_t>(std::lround(std::min(255.0, g + bg))),
         static_cast<std::uint8_t>(std::lround(std::min(255.0, b + bg))));
}

/// 3x5 glyphs, one row per 3 bits (most significant bit on the left).
const std::uint8_t* glyph(char c) {
  static const std::uint8_t digits[10][5] = {{7, 5, 5, 5, 7}, {2, 6, 2, 2, 7}, {7, 1, 7, 4, 7}, {7, 1, 7, 1, 7},
                                             {5, 5, 7, 1, 1}, {7, 4, 7, 1, 7}, {7, 4, 7, 5, 7}, {7, 1, 1, 1, 1},
                                             {7, 5, 7, 5, 7}, {7, 5, 7, 1, 7}};
  static const std::uint8_t x[5] = {5, 5, 2, 5, 5}, z[5] = {7, 1, 2, 4, 7}, y[5] = {5, 5, 2, 2, 2},
                            eq[5] = {0, 7, 0, 7, 0}, colon[5] = {0, 2, 0, 2, 0};
  if (c >= '0' && c <= '9') return digits[c - '0'];
  if (c == 'X') return x;
  if (c == 'Z') return z;
  if (c == 'Y') return y;
  if (c == '=') return eq;
  if (c == ':') return colon;
  return nullptr;
}

/// Draws `text` at 2x scale with its top-left corner at (x, y), clipped to `max_width`.
void label(Canvas& cv, int x, int y, const std::string& text, int max_width) {
  for (std::size_t k = 0; k < text.size(); ++k) {
    const int gx = x + static_cast<int>(k) * 8;
    if (gx + 6 > x + max_width) break;
    const std::uint8_t* g = glyph(text[k]);
    if (!g) continue;
    for (int r = 0; r < 5; ++r)
      for (int c = 0; c < 3; ++c)
        if (g[r] & (4 >> c))
          for (int d = 0; d < 4; ++d) cv.set(gx + 2 * c + (d & 1), y + 2 * r + (d >> 1), 220, 220, 220);
  }
}

/// Marks a panel whose slice could not be read: checkerboard with a red cross.
void cross_out(Canvas& cv, int x0, int y0, int w, int h) {
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) composite(cv, x0 + x, y0 + y, 0, 0, 0, 0);
  const int steps = std::max(w, h);
  for (int s = 0; s <= steps; ++s) {
    const int x = static_cast<int>(static_cast<long long>(s) * (w - 1) / std::max(steps, 1));
    const int y = static_cast<int>(static_cast<long long>(s) * (h - 1) / std::max(steps, 1));
    for (int t = 0; t < 2; ++t) {
      cv.set(x0 + std::min(x + t, w - 1), y0 + y, 220, 30, 30);
      cv.set(x0 + std::min(x + t, w - 1), y0 + h - 1 - y, 220, 30, 30);
    }
  }
}

/// Source ranges [lo, hi) of each of `out` output cells over `in` input cells: a box filter when
/// shrinking, nearest neighbour when enlarging.
std::vector<std::pair<int, int>> bins(int in, int out) {
  std::vector<std::pair<int, int>> b(static_cast<std::size_t>(out));
  for (int o = 0; o < out; ++o) {
    const int lo = static_cast<int>(static_cast<long long>(o) * in / out);
    const int hi = static_cast<int>(static_cast<long long>(o + 1) * in / out);
    b[static_cast<std::size_t>(o)] = {lo, std::max(hi, lo + 1)};
  }
  return b;
}

/// Sums of premultiplied colour over one row's bins, added into `acc` (4 per output column).
void accumulate_row(const std::uint8_t* row, const std::vector<std::pair<int, int>>& xb, std::vector<std::uint64_t>& acc) {
  for (std::size_t o = 0; o < xb.size(); ++o) {
    std::uint64_t r = 0, g = 0, b = 0, a = 0;
    for (int x = xb[o].first; x < xb[o].second; ++x) {
      const std::uint8_t* p = row + static_cast<std::size_t>(x) * 4;
      r += std::uint64_t{p[0]} * p[3];
      g += std::uint64_t{p[1]} * p[3];
      b += std::uint64_t{p[2]} * p[3];
      a += p[3];
    }
    acc[4 * o] += r, acc[4 * o + 1] += g, acc[4 * o + 2] += b, acc[4 * o + 3] += a;
  }
}

/// Draws slice `file` into the panel at (x0, y0) of size w x h; false if it cannot be read.
bool draw_slice(Canvas& cv, const fs::path& file, const StackConfig& c, int x0, int y0, int w, int h) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return false;
  detail::PngRowReader png(file);
  if (!png.ok() || !png.format_problem().empty() || png.width() != c.width || png.height() != c.height) return false;
  const auto xb = bins(c.width, w), yb = bins(c.height, h);
  std::vector<std::uint64_t> acc(static_cast<std::size_t>(w) * 4);
  for (int ty = 0; ty < h; ++ty) {
    std::fill(acc.begin(), acc.end(), 0);
    const auto [ylo, yhi] = yb[static_cast<std::size_t>(ty)];
    for (int y = ylo; y < yhi; ++y) {
      const std::uint8_t* row = png.row(y);
      if (!row) return false;
      accumulate_row(row, xb, acc);
    }
    for (int tx = 0; tx < w; ++tx) {
      const double n = static_cast<double>(yhi - ylo) * (xb[static_cast<std::size_t>(tx)].second - xb[static_cast<std::size_t>(tx)].first);
      const std::uint64_t* s = &acc[4 * static_cast<std::size_t>(tx)];
      composite(cv, x0 + tx, y0 + ty, s[0] / (255.0 * n), s[1] / (255.0 * n), s[2] / (255.0 * n), s[3] / n);
    }
  }
  return true;
}

}  // namespace

PreviewSummary write_preview(const fs::path& dir, const fs::path& png, int every, int width) {
  if (every < 0) throw Error("--every " + std::to_string(every) + ": expected a positive slice step (or 0: about 16 slices)");
  if (width < 64 || width > 16384) throw Error("--width " + std::to_string(width) + ": expected 64..16384 pixels");
  const StackConfig c = read_stack_config(dir);
  const auto files = detail::list_slices(dir, c.prefix);
  const auto file_of = [&](int pos) {
    const auto it = files.find(static_cast<long long>(c.start_index) + pos);
    return dir / (it != files.end() ? it->second : c.slice_name(pos));
  };

  PreviewSummary sum;
  sum.every = every > 0 ? every : std::max(1, (c.slices + 15) / 16);
  std::vector<int> shown;
  for (long long i = 0; i < c.slices; i += sum.every) shown.push_back(static_cast<int>(i));

  // Layout, in physical proportion: mm per picture pixel is the same along both panel axes.
  const double mm_w = c.width * 25.4 / c.dpi_x, mm_h = c.height * 25.4 / c.dpi_y;
  const double mm_z = c.slices * c.slice_thickness_nm * 1e-6;
  const double aspect = mm_h / mm_w;
  const int k = static_cast<int>(shown.size());
  if (k > max_thumbnails)
    throw Error("--every " + std::to_string(sum.every) + ": " + std::to_string(k) + " slices on the contact sheet; expected at most " +
                std::to_string(max_thumbnails) + " (--every " + std::to_string((c.slices + max_thumbnails - 1) / max_thumbnails) +
                " or more)");
  int cols = static_cast<int>(std::lround(std::sqrt(k * aspect * 4.0 / 3.0)));
  cols = std::clamp(cols, 1, std::min(k, (width - margin) / (16 + margin)));
  const int rows = (k + cols - 1) / cols;
  const int tw = (width - margin * (cols + 1)) / cols;
  const int th = static_cast<int>(std::clamp(std::lround(tw * aspect), 1L, 4L * width));
  int cw = width - 2 * margin;
  int ch = static_cast<int>(std::max(1L, std::lround(cw * mm_z / mm_w)));
  int z_scale = 1;
  if (ch > 2 * width) {  // a tall narrow job: shrink the section rather than let the picture grow
    ch = 2 * width;
    cw = static_cast<int>(std::clamp(std::lround(ch * mm_w / mm_z), 1L, static_cast<long>(width - 2 * margin)));
  } else if (ch < min_section) {
    // A thin job on a wide tray would give a section a few pixels tall: stretch z by a whole
    // factor, and say so in the label.
    z_scale = static_cast<int>(std::ceil(min_section * mm_w / (cw * mm_z)));
    ch = static_cast<int>(std::min(2L * width, std::max<long>(min_section, std::lround(z_scale * cw * mm_z / mm_w))));
  }
  const long long tall = margin + static_cast<long long>(rows) * (label_height + th + margin) + label_height + ch + margin;
  if (tall > max_height)
    throw Error("--width " + std::to_string(width) + ", --every " + std::to_string(sum.every) + ": the picture would be " +
                std::to_string(tall) + " pixels tall; expected at most " + std::to_string(max_height) +
                " (choose a larger --every or a smaller --width)");
  const int height = static_cast<int>(tall);
  Canvas cv(width, height);

  // Contact sheet.
  std::vector<char> drawn(shown.size());
  tbb::parallel_for(std::size_t{0}, shown.size(), [&](std::size_t t) {
    const int col = static_cast<int>(t) % cols, row = static_cast<int>(t) / cols;
    const int x0 = margin + col * (tw + margin), y0 = margin + row * (label_height + th + margin) + label_height;
    label(cv, x0, y0 - label_height + 1, std::to_string(c.start_index + shown[t]), tw);
    drawn[t] = draw_slice(cv, file_of(shown[t]), c, x0, y0, tw, th);
    if (!drawn[t]) cross_out(cv, x0, y0, tw, th);
  });
  for (std::size_t t = 0; t < shown.size(); ++t) {
    sum.shown.push_back(c.start_index + shown[t]);
    if (!drawn[t]) sum.unreadable.push_back(c.start_index + shown[t]);
  }

  // Cross-section: picture row sy shows layer (slices - 1 - sy * slices / ch), top layer on top;
  // each layer needed is decoded once, down to the middle row.
  const int section_row = c.height / 2;
  const int sx0 = margin + (width - 2 * margin - cw) / 2;
  const int sy0 = margin + rows * (label_height + th + margin) + label_height;
  label(cv, sx0, sy0 - label_height + 1, z_scale == 1 ? "XZ 1:1" : "XZ Z " + std::to_string(z_scale) + ":1", cw);
  std::vector<int> layer_of_row(static_cast<std::size_t>(ch));
  std::vector<int> layers;
  for (int sy = 0; sy < ch; ++sy) {
    const int layer = c.slices - 1 - static_cast<int>(static_cast<long long>(sy) * c.slices / ch);
    layer_of_row[static_cast<std::size_t>(sy)] = layer;
    if (layers.empty() || layers.back() != layer) layers.push_back(layer);
  }
  const auto xb = bins(c.width, cw);
  // Per needed layer: premultiplied mean colour per section column (4 bytes), or nothing.
  std::vector<std::vector<std::uint8_t>> means(layers.size());
  tbb::parallel_for(std::size_t{0}, layers.size(), [&](std::size_t li) {
    const fs::path file = file_of(layers[li]);
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) return;
    detail::PngRowReader reader(file);
    if (!reader.ok() || !reader.format_problem().empty() || reader.width() != c.width || reader.height() != c.height) return;
    const std::uint8_t* row = reader.row(section_row);
    if (!row) return;
    std::vector<std::uint64_t> acc(static_cast<std::size_t>(cw) * 4, 0);
    accumulate_row(row, xb, acc);
    std::vector<std::uint8_t> m(static_cast<std::size_t>(cw) * 4);
    for (std::size_t o = 0; o < static_cast<std::size_t>(cw); ++o) {
      const double n = xb[o].second - xb[o].first;
      for (int q = 0; q < 3; ++q) m[4 * o + static_cast<std::size_t>(q)] = static_cast<std::uint8_t>(std::lround(acc[4 * o + static_cast<std::size_t>(q)] / (255.0 * n)));
      m[4 * o + 3] = static_cast<std::uint8_t>(std::lround(acc[4 * o + 3] / n));
    }
    means[li] = std::move(m);
  });
  for (int sy = 0, li = -1, prev = -1; sy < ch; ++sy) {
    const int layer = layer_of_row[static_cast<std::size_t>(sy)];
    if (layer != prev) ++li, prev = layer;
    const auto& m = means[static_cast<std::size_t>(li)];
    for (int x = 0; x < cw; ++x) {
      if (m.empty())
        cv.set(sx0 + x, sy0 + sy, 220, 30, 30);
      else {
        const std::uint8_t* p = &m[4 * static_cast<std::size_t>(x)];
        composite(cv, sx0 + x, sy0 + sy, p[0], p[1], p[2], p[3]);
      }
    }
  }

  // The section's red rows too: every slice the picture marks, not only the contact sheet's.
  for (std::size_t li = 0; li < layers.size(); ++li)
    if (means[li].empty()) sum.unreadable.push_back(c.start_index + layers[li]);
  std::sort(sum.unreadable.begin(), sum.unreadable.end());
  sum.unreadable.erase(std::unique(sum.unreadable.begin(), sum.unreadable.end()), sum.unreadable.end());

  write_file_atomically(png, encode_png_rgba(cv.px.data(), cv.width, cv.height, 0, 0, 6));
  sum.width = width;
  sum.height = height;
  sum.section_row = section_row;
  sum.section_width = cw;
  sum.section_height = ch;
  sum.section_z_scale = z_scale;
  return sum;
}

}  // namespace trivox::io
