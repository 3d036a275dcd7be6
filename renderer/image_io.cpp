#include "image_io.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include <OpenImageIO/imageio.h>

#include "error.h"
#include "image_srgb.h"

namespace pvr::core {

namespace {

[[noreturn]] void ioError(const std::string& path, const std::string& what, const std::string& detail) {
  throw Error(ErrorCode::kIo, path + ": " + what + (detail.empty() ? "" : ": " + detail));
}

// Writes `pixels` (width x height x 4 of `type`, rows top to bottom) with
// the format OIIO picks from the path's extension.
void writeRgba(const std::string& path, int width, int height, OIIO::TypeDesc type,
               const void* pixels, const OIIO::ImageSpec& extra) {
  auto out = OIIO::ImageOutput::create(path);
  if (!out) ioError(path, "cannot write", OIIO::geterror());
  OIIO::ImageSpec spec(width, height, 4, type);
  spec.channelnames = {"R", "G", "B", "A"};
  spec.alpha_channel = 3;
  for (const OIIO::ParamValue& p : extra.extra_attribs) spec.attribute(p.name(), p.type(), p.data());
  if (!out->open(path, spec)) ioError(path, "cannot open for writing", out->geterror());
  if (!out->write_image(type, pixels)) ioError(path, "write failed", out->geterror());
  if (!out->close()) ioError(path, "write failed", out->geterror());
}

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

}  // namespace

void writeExr(const Image& image, const std::string& path) {
  const Image full = image.rect() == PixelRect{0, 0, image.frameWidth(), image.frameHeight()}
                         ? image
                         : image.toFullFrame();
  if (full.frameWidth() < 1 || full.frameHeight() < 1) ioError(path, "cannot write", "the image is empty");
  OIIO::ImageSpec extra;
  extra.attribute("compression", "zip");  // lossless
  extra.attribute("oiio:ColorSpace", "Linear");
  static_assert(sizeof(Rgba) == 4 * sizeof(float), "Rgba must be four packed floats");
  writeRgba(path, full.frameWidth(), full.frameHeight(), OIIO::TypeDesc::FLOAT,
            full.pixels().data(), extra);
}

void writePng(const Image& image, const std::array<double, 4>& background, const std::string& path) {
  if (image.frameWidth() < 1 || image.frameHeight() < 1) ioError(path, "cannot write", "the image is empty");
  const std::vector<std::uint8_t> bytes = toSrgbRgba8(image, background);
  OIIO::ImageSpec extra;
  // The bytes are straight alpha already: OIIO must not un-premultiply them again.
  extra.attribute("oiio:UnassociatedAlpha", 1);
  extra.attribute("oiio:ColorSpace", "sRGB");
  writeRgba(path, image.frameWidth(), image.frameHeight(), OIIO::TypeDesc::UINT8, bytes.data(), extra);
}

void writeImage(const Image& image, const std::array<double, 4>& background, const std::string& path) {
  const std::string ext = lowerExtension(path);
  if (ext == ".exr") return writeExr(image, path);
  if (ext == ".png") return writePng(image, background, path);
  throw Error(ErrorCode::kInvalidArgument,
              path + ": unsupported image extension '" + ext + "' (use .exr or .png)");
}

Image readExr(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) ioError(path, "cannot read", OIIO::geterror());
  if (std::string(in->format_name()) != "openexr")
    throw Error(ErrorCode::kBadFile, path + ": not an OpenEXR file (it is " + in->format_name() + ")");
  const OIIO::ImageSpec& spec = in->spec();

  // Channels by name; EXR sorts them, so positions say nothing.
  int channel[4] = {-1, -1, -1, -1};
  const char* names[4] = {"R", "G", "B", "A"};
  for (int c = 0; c < spec.nchannels; ++c)
    for (int i = 0; i < 4; ++i)
      if (spec.channel_name(c) == names[i]) channel[i] = c;
  for (int i = 0; i < 3; ++i)
    if (channel[i] < 0)
      throw Error(ErrorCode::kBadFile, path + ": no " + names[i] + " channel (need R, G, B and optionally A)");

  std::vector<float> data(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, data.data()))
    ioError(path, "read failed", in->geterror());

  // The data window, in frame coordinates, clipped to the display window.
  const PixelRect frame{0, 0, spec.full_width, spec.full_height};
  const PixelRect data_window{spec.x - spec.full_x, spec.y - spec.full_y,
                              spec.x - spec.full_x + spec.width, spec.y - spec.full_y + spec.height};
  Image image(spec.full_width, spec.full_height, data_window.intersect(frame));
  const PixelRect& r = image.rect();
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x) {
      const float* p = &data[(std::size_t(y - data_window.y0) * std::size_t(spec.width) +
                              std::size_t(x - data_window.x0)) * std::size_t(spec.nchannels)];
      image.at(x, y) = {p[channel[0]], p[channel[1]], p[channel[2]], channel[3] >= 0 ? p[channel[3]] : 1.0f};
    }
  return image;
}

Image readPngCodes(const std::string& path) {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);  // the colour as stored, never multiplied by alpha
  auto in = OIIO::ImageInput::open(path, &config);
  if (!in) ioError(path, "cannot read", OIIO::geterror());
  if (std::string(in->format_name()) != "png")
    throw Error(ErrorCode::kBadFile, path + ": not a PNG file (it is " + in->format_name() + ")");
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.nchannels < 3)
    throw Error(ErrorCode::kBadFile, path + ": " + std::to_string(spec.nchannels) + " channel(s), need R, G and B");
  std::vector<std::uint8_t> bytes(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, bytes.data()))
    ioError(path, "read failed", in->geterror());
  Image image = Image::fullFrame(spec.width, spec.height);
  for (int y = 0; y < spec.height; ++y)
    for (int x = 0; x < spec.width; ++x) {
      const std::uint8_t* p = &bytes[(std::size_t(y) * std::size_t(spec.width) + std::size_t(x)) * std::size_t(spec.nchannels)];
      image.at(x, y) = {p[0] / 255.0f, p[1] / 255.0f, p[2] / 255.0f, 0.0f};
    }
  return image;
}

}  // namespace pvr::core
