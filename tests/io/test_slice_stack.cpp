// Voxel Print stacks (io/stack_config.hpp, png_image.hpp, gcvf.hpp, stack_inspect.hpp,
// preview.hpp), checked with independent readers: PNG bytes through OpenImageIO and a
// hand-parsed chunk list, ConfigFile.xml through pugixml, the .gcvf through libzip.
// Expected voxel counts come from the pixels the tests write, counted by the test.
#include <OpenImageIO/imageio.h>
#include <tbb/parallel_for.h>
#include <zip.h>

#include <cstring>
#include <map>
#include <pugixml.hpp>
#include <random>
#include <tuple>

#include "io_test_util.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/io/gcvf.hpp"
#include "trivox/io/png_image.hpp"
#include "trivox/io/preview.hpp"
#include "trivox/io/stack_config.hpp"
#include "trivox/io/stack_inspect.hpp"

namespace {

namespace fs = std::filesystem;
using namespace trivox::io;
using trivox::io::test::check_message;
using trivox::io::test::error_of;
using trivox::io::test::slurp;
using trivox::io::test::TempDir;

using Rgba = std::array<std::uint8_t, 4>;
const Rgba cyan{0, 137, 166, 255}, magenta{198, 0, 88, 255}, white{255, 255, 255, 255}, red{255, 0, 0, 255};

StackConfig three_materials(int w, int h, int n) {
  StackConfig c;
  c.width = w;
  c.height = h;
  c.slices = n;
  c.materials = {{"VeroCyan-V", cyan, 0}, {"VeroMagenta-V", magenta, 0}, {"VeroUltraWhite", white, 0}};
  return c;
}

/// Slice k of a test stack: void, with a cyan rectangle growing with k, a magenta block and a
/// deterministic scatter of white.
std::vector<std::uint8_t> test_slice(int w, int h, int k) {
  std::vector<std::uint8_t> px(static_cast<std::size_t>(w) * h * 4, 0);
  auto put = [&](int x, int y, const Rgba& c) { std::memcpy(&px[(static_cast<std::size_t>(y) * w + x) * 4], c.data(), 4); };
  for (int y = 1; y < h / 2; ++y)
    for (int x = 1; x < std::min(w, 4 + 3 * k); ++x) put(x, y, cyan);
  for (int y = h / 2; y < h - 1; ++y)
    for (int x = w / 2; x < w - 2; ++x) put(x, y, magenta);
  for (int i = 0; i < 7 * (k + 1); ++i) put((i * 7 + k) % w, (i * 3) % h, white);
  return px;
}

/// Pixels of each colour in `px`, by the test's own count.
std::map<Rgba, std::int64_t> census(const std::vector<std::uint8_t>& px) {
  std::map<Rgba, std::int64_t> n;
  for (std::size_t i = 0; i < px.size(); i += 4) ++n[{px[i], px[i + 1], px[i + 2], px[i + 3]}];
  return n;
}

/// Writes a stack of `n` test slices with correct VoxelCounts; returns the config.
/// A stack with zero-padded names (slice_00000.png), as `--digits 5` and earlier trivox write:
/// the readers must take both forms.
StackConfig write_test_stack(const fs::path& dir, int w, int h, int n) {
  StackConfig c = three_materials(w, h, n);
  c.digits = 5;
  std::map<Rgba, std::int64_t> total;
  for (int k = 0; k < n; ++k) {
    const auto px = test_slice(w, h, k);
    for (const auto& [col, cnt] : census(px)) total[col] += cnt;
    write_file_atomically(dir / c.slice_name(k), encode_png_rgba(px.data(), w, h, c.dpi_x, c.dpi_y));
  }
  for (auto& m : c.materials) m.voxel_count = total[m.rgba];
  write_stack_config(dir, c);
  return c;
}

struct Chunk {
  std::string type;
  std::string data;
};

/// The chunk list of a PNG, parsed by hand (a reader independent of libpng).
std::vector<Chunk> png_chunks(const std::string& png) {
  REQUIRE(png.size() >= 8);
  REQUIRE(png.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0);
  std::vector<Chunk> out;
  std::size_t i = 8;
  while (i + 12 <= png.size()) {
    const auto b = [&](std::size_t k) { return static_cast<std::uint32_t>(static_cast<unsigned char>(png[k])); };
    const std::uint32_t n = b(i) << 24 | b(i + 1) << 16 | b(i + 2) << 8 | b(i + 3);
    out.push_back({png.substr(i + 4, 4), png.substr(i + 8, n)});
    i += 12 + n;
  }
  return out;
}

std::uint32_t be32(const std::string& s, std::size_t at) {
  std::uint32_t v = 0;
  for (std::size_t k = 0; k < 4; ++k) v = v << 8 | static_cast<unsigned char>(s[at + k]);
  return v;
}

/// Reads a PNG file with OpenImageIO, colours as stored.
struct OiioImage {
  int width = 0, height = 0, channels = 0;
  std::vector<std::uint8_t> px;
  float xres = 0, yres = 0;
  std::string unit;
};
OiioImage oiio_read(const fs::path& p) {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(p.string(), &config);
  REQUIRE(in);
  const auto& spec = in->spec();
  OiioImage img{spec.width, spec.height, spec.nchannels, {}, spec.get_float_attribute("XResolution"),
                spec.get_float_attribute("YResolution"), spec.get_string_attribute("ResolutionUnit")};
  img.px.resize(static_cast<std::size_t>(img.width) * img.height * img.channels);
  REQUIRE(in->read_image(0, 0, 0, img.channels, OIIO::TypeDesc::UINT8, img.px.data()));
  return img;
}

void corrupt_by_truncation(const fs::path& p) {
  const std::string bytes = slurp(p);
  std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes.substr(0, bytes.size() / 2);
}

}  // namespace

TEST_CASE("encode_png_rgba: OpenImageIO reads back the same pixels and pHYs", "[io][stack][png]") {
  TempDir dir("png");
  const int w = 37, h = 23;
  std::vector<std::uint8_t> px(static_cast<std::size_t>(w) * h * 4);
  std::mt19937 rng(7);
  for (auto& b : px) b = static_cast<std::uint8_t>(rng());
  for (std::size_t i = 3; i < px.size(); i += 16) px[i] = 0;  // transparent, colour kept as given
  const std::string png = encode_png_rgba(px.data(), w, h, 600, 300);
  write_file_atomically(dir.path() / "a.png", png);
  const OiioImage img = oiio_read(dir.path() / "a.png");
  CHECK(img.width == w);
  CHECK(img.height == h);
  REQUIRE(img.channels == 4);
  CHECK(img.px == px);
  CHECK(img.unit == "inch");
  CHECK(img.xres == Approx(600).epsilon(1e-5));  // pHYs holds whole pixels per metre
  CHECK(img.yres == Approx(300).epsilon(1e-5));

  // The chunks themselves: pHYs in pixels per metre, rounded (600 dpi = 23622.05 px/m), no
  // text or time chunks, so the bytes depend on the pixels only.
  const auto chunks = png_chunks(png);
  REQUIRE(chunks.front().type == "IHDR");
  CHECK(be32(chunks.front().data, 0) == static_cast<std::uint32_t>(w));
  CHECK(chunks.front().data[8] == 8);  // bit depth
  CHECK(chunks.front().data[9] == 6);  // colour type RGBA
  CHECK(chunks.back().type == "IEND");
  bool phys = false;
  for (const auto& c : chunks) {
    CHECK(c.type != "tEXt");
    CHECK(c.type != "zTXt");
    CHECK(c.type != "iTXt");
    CHECK(c.type != "tIME");
    if (c.type == "pHYs") {
      phys = true;
      CHECK(be32(c.data, 0) == 23622);
      CHECK(be32(c.data, 4) == 11811);
      CHECK(c.data[8] == 1);  // metre
    }
  }
  CHECK(phys);
  CHECK(encode_png_rgba(px.data(), w, h, 600, 300) == png);

  // 254 dpi is exactly 10000 px/m: rounding, not truncation of 9999.99...
  const auto chunks254 = png_chunks(encode_png_rgba(px.data(), w, h, 254, 254));
  for (const auto& c : chunks254)
    if (c.type == "pHYs") CHECK(be32(c.data, 0) == 10000);
  // No dpi: no pHYs.
  for (const auto& c : png_chunks(encode_png_rgba(px.data(), w, h, 0, 0))) CHECK(c.type != "pHYs");

  // Our own decoder agrees.
  const RgbaImage back = decode_png_rgba(png, "a.png");
  CHECK(back.pixels == px);
  CHECK(back.dpi_x == Approx(600).epsilon(1e-5));
  CHECK(back.dpi_y == Approx(300).epsilon(1e-5));

  check_message(error_of([&] { encode_png_rgba(px.data(), 0, h, 600, 300); }), {"0 x 23", "expected a positive"});
  check_message(error_of([&] { decode_png_rgba(png.substr(0, png.size() / 2), "half.png"); }), {"half.png", "expected a complete PNG"});
  check_message(error_of([&] { decode_png_rgba("not a png", "text.png"); }), {"text.png: not a PNG", "expected a PNG file"});
}

TEST_CASE("encode_png_indexed: the bytes of encode_png_rgba of the painted image", "[io][stack][png]") {
  // Widths around the eight-pixel vectors and the painting strips (32768 / width rows each),
  // heights of several strips; indices of a small palette with void (the vector path), and
  // every other byte value (the table of 256) scattered among them.
  std::array<std::uint32_t, 256> colours{};
  std::mt19937 rng(5);
  for (auto& c : colours) c = static_cast<std::uint32_t>(rng());
  colours[255] = 0;
  for (const auto& [w, h, mixed] : {std::tuple{1, 5, false}, {7, 3, true}, {9, 4000, false}, {1003, 70, false}, {1003, 70, true}}) {
    INFO(w << " x " << h << (mixed ? ", every index" : ", indices 0..6 and 255"));
    const auto n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
    std::vector<std::uint8_t> index(n);
    for (std::size_t j = 0; j < n; ++j) {
      const auto r = rng();
      index[j] = r % 5 == 0 ? 255 : static_cast<std::uint8_t>(r % 7);
      if (mixed && r % 13 == 0) index[j] = static_cast<std::uint8_t>(rng());
    }
    std::vector<std::uint8_t> rgba(n * 4);
    for (std::size_t j = 0; j < n; ++j) std::memcpy(&rgba[4 * j], &colours[index[j]], 4);
    const std::string png = encode_png_indexed(index.data(), w, h, colours, 600, 300);
    CHECK(png == encode_png_rgba(rgba.data(), w, h, 600, 300));
    CHECK(decode_png_rgba(png, "indexed.png").pixels == rgba);
  }
  const std::uint8_t one = 0;
  check_message(error_of([&] { encode_png_indexed(&one, 1, 0, colours, 600, 300); }), {"1 x 0", "expected a positive"});
  check_message(error_of([&] { encode_png_indexed(&one, 1, 1, colours, 600, 300, 10); }), {"level 10", "expected 0..9"});
}

TEST_CASE("encode_png_rgba gives the same bytes from many threads", "[io][stack][png]") {
  // The slicer encodes layers in parallel; the bytes must not depend on it.
  const int w = 300, h = 200, n = 16;
  std::vector<std::string> serial(n), parallel(n);
  std::vector<std::vector<std::uint8_t>> slices;
  for (int k = 0; k < n; ++k) slices.push_back(test_slice(w, h, k));
  for (int k = 0; k < n; ++k) serial[static_cast<std::size_t>(k)] = encode_png_rgba(slices[static_cast<std::size_t>(k)].data(), w, h, 600, 300);
  tbb::parallel_for(0, n, [&](int k) {
    parallel[static_cast<std::size_t>(k)] = encode_png_rgba(slices[static_cast<std::size_t>(k)].data(), w, h, 600, 300);
  });
  CHECK(parallel == serial);
  for (int k = 0; k < n; ++k) CHECK(decode_png_rgba(serial[static_cast<std::size_t>(k)], "s").pixels == slices[static_cast<std::size_t>(k)]);
}

TEST_CASE("decode_png_rgba gives RGB files alpha 255", "[io][stack][png]") {
  TempDir dir("rgb");
  const int w = 5, h = 4;
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(w) * h * 3);
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<std::uint8_t>(i * 11);
  {
    auto out = OIIO::ImageOutput::create((dir.path() / "rgb.png").string());
    REQUIRE(out);
    REQUIRE(out->open((dir.path() / "rgb.png").string(), OIIO::ImageSpec(w, h, 3, OIIO::TypeDesc::UINT8)));
    REQUIRE(out->write_image(OIIO::TypeDesc::UINT8, rgb.data()));
    REQUIRE(out->close());
  }
  const RgbaImage img = decode_png_rgba(slurp(dir.path() / "rgb.png"), "rgb.png");
  REQUIRE(img.pixels.size() == static_cast<std::size_t>(w) * h * 4);
  for (std::size_t k = 0; k < static_cast<std::size_t>(w) * h; ++k) {
    CHECK(img.pixels[4 * k] == rgb[3 * k]);
    CHECK(img.pixels[4 * k + 2] == rgb[3 * k + 2]);
    CHECK(img.pixels[4 * k + 3] == 255);
  }
}

TEST_CASE("slice names", "[io][stack]") {
  StackConfig c;
  // Unpadded by default, as the public writers name slices.
  CHECK(c.slice_name(0) == "slice_0.png");
  CHECK(c.slice_name(123456) == "slice_123456.png");
  c.digits = 5;
  CHECK(c.slice_name(0) == "slice_00000.png");
  c.start_index = 7;
  CHECK(c.slice_name(5) == "slice_00012.png");
  c.digits = 2;
  CHECK(c.slice_name(100) == "slice_107.png");
  c.digits = 0;
  c.prefix = "layer_";
  CHECK(c.slice_name(0) == "layer_7.png");
  // 600 x 300 dpi, 27 um: 25.4/600 * 25.4/300 * 0.027 mm^3.
  CHECK(c.voxel_volume_mm3() == Approx(25.4 / 600 * 25.4 / 300 * 0.027).epsilon(1e-15));
}

TEST_CASE("ConfigFile.xml round trip, and what pugixml reads in it", "[io][stack][xml]") {
  StackConfig c = three_materials(11575, 4606, 7411);
  c.dpi_x = 1200;
  c.start_index = 3;
  c.prefix = "layer_";
  c.materials[0].voxel_count = 123456789012LL;
  c.materials[2].name = "A&B <white> \"x\"";
  const std::string text = config_xml(c);
  StackConfig back = parse_config_xml(text, "ConfigFile.xml");
  CHECK(back == c);

  pugi::xml_document doc;
  REQUIRE(doc.load_string(text.c_str()));
  const pugi::xml_node root = doc.child("GCVF");
  REQUIRE(root);
  CHECK(root.child("Version").text().as_int() == 2);
  CHECK(std::string(root.child("Resolution").child_value("XDpi")) == "1200");
  CHECK(std::string(root.child("Resolution").child_value("YDpi")) == "300");
  CHECK(std::string(root.child("Resolution").child_value("SliceThicknessNanoMeter")) == "27000");
  CHECK(root.child("SliceDimensions").child("SliceWidth").text().as_int() == 11575);
  CHECK(root.child("SliceDimensions").child("SliceHeight").text().as_int() == 4606);
  CHECK(root.child("SliceRange").child("StartIndex").text().as_int() == 3);
  CHECK(root.child("SliceRange").child("NumberOfSlices").text().as_int() == 7411);
  CHECK(std::string(root.child_value("ImageFilePrefix")) == "layer_");
  const pugi::xml_node list = root.child("MaterialList");
  CHECK(std::string(list.child_value("BackGroundMaterialRGBA")) == "0 0 0 0");
  std::vector<pugi::xml_node> mats;
  for (auto m : list.children("Material")) mats.push_back(m);
  REQUIRE(mats.size() == 3);
  CHECK(std::string(mats[0].child_value("Name")) == "VeroCyan-V");
  CHECK(std::string(mats[0].child_value("RGBA")) == "0 137 166 255");
  CHECK(std::string(mats[0].child_value("VoxelCount")) == "123456789012");
  CHECK(std::string(mats[1].child_value("RGBA")) == "198 0 88 255");
  CHECK(std::string(mats[2].child_value("Name")) == "A&B <white> \"x\"");

  SECTION("round numbers are written without an exponent") {
    // 0.1 mm layers at 100000 dpi: shortest round-trip notation would give 1e+05, which readers
    // of an integer field (Python's int, JavaScript's parseInt) reject or misread.
    c.slice_thickness_nm = 0.1 * 1e6;
    c.dpi_x = 1e5;
    c.dpi_y = 2e4;
    pugi::xml_document d2;
    REQUIRE(d2.load_string(config_xml(c).c_str()));
    const pugi::xml_node res = d2.child("GCVF").child("Resolution");
    CHECK(std::string(res.child_value("SliceThicknessNanoMeter")) == "100000");
    CHECK(std::string(res.child_value("XDpi")) == "100000");
    CHECK(std::string(res.child_value("YDpi")) == "20000");
    CHECK(parse_config_xml(config_xml(c), "ConfigFile.xml") == c);
  }

  SECTION("numbers that are not whole are refused, not written as 1000.9999999999999") {
    // What parseInt (voxelprint-preview) or int() would make of them: another resolution.
    StackConfig f = c;
    f.dpi_x = 599.5;
    check_message(error_of([&] { config_xml(f); }), {"XDpi, YDpi 599.5, 300", "expected whole dots per inch"});
    f = c;
    f.slice_thickness_nm = 0.001001 * 1e6;  // binary noise: the job rounds it (stack_config_of) first
    check_message(error_of([&] { config_xml(f); }),
                  {"SliceThicknessNanoMeter 1000.9999999999999", "expected a whole number of nanometres"});
  }

  SECTION("MaxNumberOfColors bounds the material list") {
    StackConfig f = c;
    f.max_colors = 2;
    check_message(error_of([&] { config_xml(f); }),
                  {"MaterialList: 3 materials (VeroCyan-V, VeroMagenta-V, A&B <white> \"x\")", "expected at most 2"});
    f.max_colors = 7;
    pugi::xml_document d2;
    REQUIRE(d2.load_string(config_xml(f).c_str()));
    CHECK(d2.child("GCVF").child("MaxNumberOfColors").text().as_int() == 7);
    CHECK(parse_config_xml(config_xml(f), "ConfigFile.xml") == f);
  }

  SECTION("a black background: declared, read back, and no material may be black") {
    StackConfig f = c;
    f.background = stack_background("black");
    CHECK(f.background == Rgba{0, 0, 0, 255});
    CHECK(stack_background_name(f.background) == "black");
    CHECK(stack_background_name(stack_background("transparent")) == "transparent");
    pugi::xml_document d2;
    REQUIRE(d2.load_string(config_xml(f).c_str()));
    CHECK(std::string(d2.child("GCVF").child("MaterialList").child_value("BackGroundMaterialRGBA")) == "0 0 0 255");
    CHECK(parse_config_xml(config_xml(f), "ConfigFile.xml") == f);
    f.materials[1].rgba = Rgba{0, 0, 0, 255};
    check_message(error_of([&] { config_xml(f); }), {"is the background colour", "expected a colour of its own"});
    check_message(error_of([&] { stack_background("white"); }), {"--background white: unknown; expected transparent or black"});
  }

  SECTION("a flat layout (elements directly under the root) reads too") {
    const std::string flat =
        "<GCVF><Version>1</Version><XDpi>600</XDpi><YDpi>300</YDpi><SliceThicknessNanoMeter>27000"
        "</SliceThicknessNanoMeter><SliceWidth>10</SliceWidth><SliceHeight>5</SliceHeight><StartIndex>0"
        "</StartIndex><NumberOfSlices>2</NumberOfSlices><ImageFilePrefix>s</ImageFilePrefix><MaterialList>"
        "<Material><Name>M</Name><RGBA> 1, 2, 3, 255 </RGBA><VoxelCount>4</VoxelCount></Material>"
        "</MaterialList></GCVF>";
    const StackConfig f = parse_config_xml(flat, "flat.xml");
    CHECK(f.version == 1);
    CHECK(f.width == 10);
    CHECK(f.prefix == "s");
    REQUIRE(f.materials.size() == 1);
    CHECK(f.materials[0].rgba == Rgba{1, 2, 3, 255});
    CHECK(f.materials[0].voxel_count == 4);
  }
}

TEST_CASE("ConfigFile.xml errors name the file, the element and what was expected", "[io][stack][xml][bad]") {
  const StackConfig c = three_materials(100, 50, 3);
  const std::string good = config_xml(c);
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string t = good;
    const auto at = t.find(from);
    REQUIRE(at != std::string::npos);
    return t.replace(at, from.size(), to);
  };
  const auto msg = [](const std::string& text) { return error_of([&] { parse_config_xml(text, "dir/ConfigFile.xml"); }); };
  check_message(msg(with("<XDpi>600</XDpi>", "")), {"dir/ConfigFile.xml: GCVF/Resolution/XDpi: missing; expected"});
  check_message(msg(with("<XDpi>600</XDpi>", "<XDpi>abc</XDpi>")),
                {"dir/ConfigFile.xml: GCVF/Resolution/XDpi (line ", "\"abc\" is not a number; expected a positive number"});
  check_message(msg(with("<YDpi>300</YDpi>", "<YDpi>-3</YDpi>")), {"GCVF/Resolution/YDpi", "-3; expected a positive"});
  check_message(msg(with("<SliceWidth>100</SliceWidth>", "<SliceWidth>1.5</SliceWidth>")),
                {"GCVF/SliceDimensions/SliceWidth", "not an integer; expected a whole number"});
  check_message(msg(with("<NumberOfSlices>3</NumberOfSlices>", "<NumberOfSlices>0</NumberOfSlices>")),
                {"GCVF/SliceRange/NumberOfSlices", "0; expected a slice count of 1..1000000"});
  check_message(msg(with("<RGBA>198 0 88 255</RGBA>", "<RGBA>198 0 88</RGBA>")),
                {"GCVF/MaterialList/Material[1]/RGBA (line ", "expected four integers 0..255"});
  check_message(msg(with("<RGBA>198 0 88 255</RGBA>", "<RGBA>0 137 166 255</RGBA>")),
                {"Material[1]/RGBA", "also the colour of \"VeroCyan-V\"; expected distinct colours"});
  check_message(msg(with("<RGBA>198 0 88 255</RGBA>", "<RGBA>198 0 88 0</RGBA>")), {"transparent; expected alpha > 0"});
  check_message(msg(with("<VoxelCount>0</VoxelCount>", "")), {"Material[0]", "no <VoxelCount>; expected"});
  check_message(msg(with("<ImageFilePrefix>slice_</ImageFilePrefix>", "<ImageFilePrefix>../x</ImageFilePrefix>")),
                {"GCVF/ImageFilePrefix", "expected a file-name prefix without '/'"});
  check_message(msg(good.substr(0, good.size() / 2)), {"dir/ConfigFile.xml: line ", "malformed XML", "expected a well-formed"});
  check_message(msg(""), {"dir/ConfigFile.xml", "expected"});

  // The writer refuses what the reader would.
  StackConfig bad = c;
  bad.materials[1].rgba = cyan;
  check_message(error_of([&] { config_xml(bad); }), {"repeats an earlier material", "expected distinct colours"});
  bad = c;
  bad.dpi_x = 0;
  check_message(error_of([&] { config_xml(bad); }), {"XDpi 0; expected a positive number"});
}

TEST_CASE("inspect_stack counts what the slices hold", "[io][stack][inspect]") {
  TempDir dir("inspect");
  const int w = 53, h = 31, n = 6;
  const StackConfig c = write_test_stack(dir.path(), w, h, n);
  // Truth: the test's own census of the pixels it wrote.
  std::map<Rgba, std::int64_t> total;
  for (int k = 0; k < n; ++k)
    for (const auto& [col, cnt] : census(test_slice(w, h, k))) total[col] += cnt;

  StackReport r = inspect_stack(dir.path());
  CHECK(r.valid());
  CHECK(r.present == n);
  CHECK(r.missing.empty());
  CHECK(r.corrupt.empty());
  CHECK(r.config.digits == 5);
  REQUIRE(r.voxels_per_material.size() == 3);
  CHECK(r.voxels_per_material[0] == total[cyan]);
  CHECK(r.voxels_per_material[1] == total[magenta]);
  CHECK(r.voxels_per_material[2] == total[white]);
  CHECK(r.void_voxels == total[Rgba{0, 0, 0, 0}]);
  CHECK(r.voxels + r.void_voxels == static_cast<std::int64_t>(w) * h * n);
  const double voxel = 25.4 / 600 * 25.4 / 300 * 0.027;
  CHECK(r.voxel_volume_mm3 == Approx(voxel).epsilon(1e-14));
  CHECK(r.volume_per_material_mm3[1] == Approx(static_cast<double>(total[magenta]) * voxel).epsilon(1e-12));
  CHECK(r.volume_mm3 == Approx(static_cast<double>(r.voxels) * voxel).epsilon(1e-12));

  SECTION("a missing, a truncated, a foreign-coloured and a wrong-sized slice are reported") {
    fs::remove(dir.path() / c.slice_name(4));
    corrupt_by_truncation(dir.path() / c.slice_name(2));
    auto px = test_slice(w, h, 3);
    std::memcpy(&px[(static_cast<std::size_t>(5) * w + 9) * 4], red.data(), 4);
    write_file_atomically(dir.path() / c.slice_name(3), encode_png_rgba(px.data(), w, h, 600, 300));
    const auto small = test_slice(w - 1, h, 5);
    write_file_atomically(dir.path() / c.slice_name(5), encode_png_rgba(small.data(), w - 1, h, 600, 300));
    fs::copy_file(dir.path() / c.slice_name(0), dir.path() / "slice_00099.png");

    r = inspect_stack(dir.path());
    CHECK_FALSE(r.valid());
    CHECK(r.present == n - 1);
    CHECK(r.missing == std::vector<int>{4});
    CHECK(r.corrupt == std::vector<int>{2, 3, 5});
    CHECK(r.extra == std::vector<int>{99});
    CHECK(r.foreign_pixels == 1);
    CHECK(r.count_mismatch.empty());  // not judged on an incomplete read
    REQUIRE(r.problems.size() == 4);
    CHECK(r.problems[0].file == "slice_00002.png");
    check_message(r.problems[0].reason, {"truncated: chunk IDAT", "expected a complete PNG file"});
    check_message(r.problems[1].reason, {"1 pixel of foreign colours", "(9, 5) = 255 0 0 255", "expected only MaterialList colours"});
    check_message(r.problems[2].reason, {"missing"});
    check_message(r.problems[3].reason, {"52 x 31 pixels; expected 53 x 31"});
    // Slices 0, 1 and (apart from its red pixel) 3 are counted.
    const std::int64_t cyan_counted = census(test_slice(w, h, 0))[cyan] + census(test_slice(w, h, 1))[cyan] + census(px)[cyan];
    CHECK(r.voxels_per_material[0] == cyan_counted);
  }

  SECTION("a VoxelCount the pixels contradict makes the stack invalid") {
    StackConfig wrong = c;
    wrong.materials[1].voxel_count += 1;
    write_stack_config(dir.path(), wrong);
    r = inspect_stack(dir.path());
    CHECK_FALSE(r.valid());
    CHECK(r.count_mismatch == std::vector<int>{1});
  }

  SECTION("a folder without a usable ConfigFile.xml is bad input") {
    check_message(error_of([&] { inspect_stack(dir.path() / "nothing"); }), {"nothing: no such folder; expected a slice folder"});
    fs::remove(dir.path() / "ConfigFile.xml");
    check_message(error_of([&] { inspect_stack(dir.path()); }), {"no ConfigFile.xml; expected a slice folder holding ConfigFile.xml"});
    std::ofstream(dir.path() / "ConfigFile.xml") << "<GCVF><Version>2</Version>";
    check_message(error_of([&] { inspect_stack(dir.path()); }), {"ConfigFile.xml: line 1", "malformed XML"});
  }
}

TEST_CASE("inspect_stack finds unpadded slice names and a start index", "[io][stack][inspect]") {
  TempDir dir("unpadded");
  StackConfig c = three_materials(8, 4, 12);
  c.prefix = "layer_";
  c.digits = 0;
  c.start_index = 5;
  std::int64_t cyan_total = 0;
  for (int k = 0; k < c.slices; ++k) {
    const auto px = test_slice(c.width, c.height, k);
    cyan_total += census(px)[cyan];
    write_file_atomically(dir.path() / c.slice_name(k), encode_png_rgba(px.data(), c.width, c.height, 600, 300));
  }
  CHECK(fs::exists(dir.path() / "layer_5.png"));
  CHECK(fs::exists(dir.path() / "layer_16.png"));
  c.materials[0].voxel_count = cyan_total;
  for (int m : {1, 2}) {
    std::int64_t t = 0;
    for (int k = 0; k < c.slices; ++k) t += census(test_slice(c.width, c.height, k))[c.materials[static_cast<std::size_t>(m)].rgba];
    c.materials[static_cast<std::size_t>(m)].voxel_count = t;
  }
  write_stack_config(dir.path(), c);
  const StackReport r = inspect_stack(dir.path());
  CHECK(r.valid());
  CHECK(r.present == 12);
  CHECK(r.config.digits == 1);
  CHECK(r.config.slice_name(11) == "layer_16.png");
  CHECK(r.voxels_per_material[0] == cyan_total);
}

TEST_CASE("zip_stack packs ConfigFile.xml and the slices, reproducibly", "[io][stack][zip]") {
  TempDir dir("zip");
  const fs::path stack = dir.path() / "stack";
  fs::create_directories(stack);
  const StackConfig c = write_test_stack(stack, 20, 10, 4);
  std::ofstream(stack / "manifest.json") << "{}";  // not part of the .gcvf
  const fs::path gcvf = dir.path() / "job.gcvf";
  zip_stack(stack, gcvf);

  int err = 0;
  zip_t* z = zip_open(gcvf.c_str(), ZIP_RDONLY, &err);
  REQUIRE(z);
  std::vector<std::string> expected{"ConfigFile.xml"};
  for (int k = 0; k < c.slices; ++k) expected.push_back(c.slice_name(k));
  REQUIRE(zip_get_num_entries(z, 0) == static_cast<zip_int64_t>(expected.size()));
  for (std::size_t i = 0; i < expected.size(); ++i) {
    zip_stat_t st;
    REQUIRE(zip_stat_index(z, i, 0, &st) == 0);
    CHECK(std::string(st.name) == expected[i]);
    CHECK(st.comp_method == (i == 0 ? ZIP_CM_DEFLATE : ZIP_CM_STORE));
    std::string bytes(st.size, '\0');
    zip_file_t* f = zip_fopen_index(z, i, 0);
    REQUIRE(f);
    CHECK(zip_fread(f, bytes.data(), st.size) == static_cast<zip_int64_t>(st.size));
    zip_fclose(f);
    CHECK(bytes == slurp(stack / expected[i]));
  }
  zip_close(z);

  // The same stack, files rewritten later, gives the same bytes; no temporary is left behind.
  const std::string first = slurp(gcvf);
  for (int k = 0; k < c.slices; ++k) {
    const std::string s = slurp(stack / c.slice_name(k));
    fs::remove(stack / c.slice_name(k));
    write_file_atomically(stack / c.slice_name(k), s);
  }
  zip_stack(stack, dir.path() / "again.gcvf");
  CHECK(slurp(dir.path() / "again.gcvf") == first);
  for (const auto& e : fs::directory_iterator(dir.path())) CHECK(e.path().filename().string().find(".tmp") == std::string::npos);

  fs::remove(stack / c.slice_name(2));
  check_message(error_of([&] { zip_stack(stack, dir.path() / "broken.gcvf"); }),
                {"slice_00002.png: missing; expected all 4 slices"});
  CHECK_FALSE(fs::exists(dir.path() / "broken.gcvf"));
}

TEST_CASE("write_preview draws the stack in physical proportions", "[io][stack][preview]") {
  TempDir dir("preview");
  const int w = 60, h = 30, n = 20;
  const StackConfig c = write_test_stack(dir.path(), w, h, n);
  const fs::path out = dir.path() / "preview.png";
  const PreviewSummary s = write_preview(dir.path(), out, 0, 800);
  CHECK(s.every == 2);  // ceil(20 / 16)
  CHECK(s.shown == std::vector<int>{0, 2, 4, 6, 8, 10, 12, 14, 16, 18});
  CHECK(s.unreadable.empty());
  CHECK(s.section_row == h / 2);
  // Section: 60 columns at 600 dpi = 2.54 mm wide, 20 layers of 27 um = 0.54 mm tall.
  CHECK(s.section_height == Approx(s.section_width * 0.54 / 2.54).margin(1.0));

  const OiioImage img = oiio_read(out);
  CHECK(img.width == s.width);
  CHECK(img.height == s.height);
  REQUIRE(img.channels == 4);
  std::map<Rgba, std::int64_t> colours;
  for (std::size_t i = 0; i < img.px.size(); i += 4) ++colours[{img.px[i], img.px[i + 1], img.px[i + 2], img.px[i + 3]}];
  for (const auto& [col, cnt] : colours) CHECK(col[3] == 255);  // opaque
  // Enlarged thumbnails show each material's exact colour, and void as the checkerboard.
  CHECK(colours[cyan] > 0);
  CHECK(colours[magenta] > 0);
  CHECK(colours[Rgba{72, 72, 72, 255}] > 0);

  fs::remove(dir.path() / c.slice_name(4));
  const PreviewSummary s2 = write_preview(dir.path(), out, 4, 400);
  CHECK(s2.shown == std::vector<int>{0, 4, 8, 12, 16});
  CHECK(s2.unreadable == std::vector<int>{4});
  for (const auto& e : fs::directory_iterator(dir.path())) CHECK(e.path().filename().string().find(".tmp") == std::string::npos);

  CHECK(s.section_z_scale == 1);

  // Two layers under a 2.54 mm wide slice: the true section would be 17 px tall; stretched
  // 3 times (the least whole factor reaching 48 px) it is 784 * 3 * 0.054 / 2.54 = 50 px.
  TempDir thin("preview-thin");
  write_test_stack(thin.path(), w, h, 2);
  const PreviewSummary s3 = write_preview(thin.path(), thin.path() / "p.png", 0, 800);
  CHECK(s3.section_z_scale == 3);
  CHECK(s3.section_height == 50);

  check_message(error_of([&] { write_preview(dir.path(), out, -1, 800); }), {"--every -1", "expected"});
  check_message(error_of([&] { write_preview(dir.path(), out, 0, 10); }), {"--width 10", "expected 64..16384"});
  // A slice 30 times as tall as wide (4 x 60 px at 600 x 300 dpi): two 8k-wide thumbnails
  // side by side would be 245k pixels tall.
  TempDir tall("preview-tall");
  write_test_stack(tall.path(), 4, 60, 2);
  check_message(error_of([&] { write_preview(tall.path(), tall.path() / "p.png", 1, 16384); }),
                {"pixels tall; expected at most 32768"});
  CHECK(write_preview(tall.path(), tall.path() / "p.png", 1, 800).height <= 32768);
}
