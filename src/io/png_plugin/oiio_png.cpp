// The module trivox_png: PNG encoding and decoding in memory through OpenImageIO, behind the
// interface of src/io/png_codec.hpp. Only this file links OpenImageIO (and its ~260 libraries);
// trivox_core loads it on first use (png_codec()). It makes OpenImageIO's calls and reports what
// OpenImageIO says; wording, checks and trivox::Error stay in trivox_core.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <memory>
#include <string>
#include <vector>

#include "../png_codec.hpp"

namespace trivox::io::detail {
namespace {

class OiioEncoder final : public PngEncoder {
public:
  OiioEncoder() : proxy_(buffer_) {}
  /// false when OpenImageIO has no PNG writer.
  bool create() {
    out_ = OIIO::ImageOutput::create("png", &proxy_);
    return out_ != nullptr;
  }
  bool open(const PngEncodeSettings& s) override {
    OIIO::ImageSpec spec(s.width, s.height, 4, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:UnassociatedAlpha", 1);  // the pixels are final colours: store them as given
    spec.attribute("png:compressionLevel", s.level);
    spec.attribute("png:filter", 0x08);  // PNG_FILTER_NONE (png.h): no per-row filter trials
    if (s.phys) {
      // pHYs holds whole pixels per metre and OpenImageIO truncates: the caller rounded them.
      spec.attribute("ResolutionUnit", "m");
      spec.attribute("XResolution", s.pixels_per_metre_x);
      spec.attribute("YResolution", s.pixels_per_metre_y);
    }
    buffer_.reserve(static_cast<std::size_t>(s.width) * static_cast<std::size_t>(s.height) / 16 + 4096);
    return out_->open("slice.png", spec);
  }
  bool image(const std::uint8_t* rgba) override { return out_->write_image(OIIO::TypeDesc::UINT8, rgba); }
  bool rows(int y0, int y1, const std::uint8_t* rgba) override {
    return out_->write_scanlines(y0, y1, 0, OIIO::TypeDesc::UINT8, rgba);
  }
  bool finish(std::string& png) override {
    if (!out_->close()) return false;
    png.assign(buffer_.begin(), buffer_.end());
    return true;
  }
  std::string error() override { return out_->geterror(); }

private:
  std::vector<unsigned char> buffer_;
  OIIO::Filesystem::IOVecOutput proxy_;
  std::unique_ptr<OIIO::ImageOutput> out_;
};

class OiioDecoder final : public PngDecoder {
public:
  OiioDecoder(const char* bytes, std::size_t size) : proxy_(bytes, size) {}
  ~OiioDecoder() override {
    if (in_) {
      in_->close();
      (void)in_->geterror();  // nothing may stay pending (OpenImageIO would print it)
    }
  }
  /// false when OpenImageIO cannot open the bytes as an image (OIIO::geterror() says why).
  bool open(const std::string& name) {
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);  // keep colours as stored, never premultiply
    // The PNG reader's open() takes the proxy from the configuration (and drops one passed otherwise).
    OIIO::Filesystem::IOProxy* proxy = &proxy_;
    config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
    in_ = OIIO::ImageInput::open(name, &config, proxy);
    if (!in_) return false;
    const OIIO::ImageSpec& s = in_->spec();
    spec_.width = s.width;
    spec_.height = s.height;
    spec_.channels = s.nchannels;
    spec_.bits = static_cast<int>(s.format.size() * 8);
    spec_.resolution_unit = s.get_string_attribute("ResolutionUnit");
    spec_.x_resolution = s.get_float_attribute("XResolution", 0.0f);
    spec_.y_resolution = s.get_float_attribute("YResolution", 0.0f);
    return true;
  }
  const PngSpec& spec() const override { return spec_; }
  bool rows(int y0, int y1, int channels, std::uint8_t* out) override {
    return in_->read_scanlines(0, 0, y0, y1, 0, 0, channels, OIIO::TypeDesc::UINT8, out);
  }
  bool image(int channels, std::uint8_t* out) override {
    return in_->read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, out);
  }
  std::string error() override { return in_->geterror(); }

private:
  OIIO::Filesystem::IOMemReader proxy_;  // outlives in_
  std::unique_ptr<OIIO::ImageInput> in_;
  PngSpec spec_;
};

class OiioCodec final : public PngCodec {
public:
  std::unique_ptr<PngEncoder> encoder(std::string& error) const override {
    auto e = std::make_unique<OiioEncoder>();
    if (!e->create()) {
      error = OIIO::geterror();
      return nullptr;
    }
    return e;
  }
  std::unique_ptr<PngDecoder> decoder(const char* bytes, std::size_t size, const std::string& name,
                                      std::string& error) const override {
    auto d = std::make_unique<OiioDecoder>(bytes, size);
    if (!d->open(name)) {
      error = OIIO::geterror();
      return nullptr;
    }
    return d;
  }
};

}  // namespace
}  // namespace trivox::io::detail

extern "C" [[gnu::visibility("default")]] const trivox::io::detail::PngCodec* trivox_png_codec_v1() {
  static const trivox::io::detail::OiioCodec codec{};
  return &codec;
}
