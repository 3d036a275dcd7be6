// The ImageFrame pixel codec (protocol/pixel_codec.h): every compression and
// format round-trips, the sender falls back to none when compressing does
// not pay, and damaged pixels are refused with a code and a text naming what
// is wrong.
#include <catch2/catch.hpp>

#include <zlib.h>

#include <random>

#include "pvr_protocol.h"

using namespace pvr::proto;

namespace {

constexpr Compression kCompressions[] = {Compression::kNone, Compression::kRle, Compression::kZlib};
constexpr PixelFormat kFormats[] = {PixelFormat::kRgb8, PixelFormat::kRgba8};

ImageFrame frameOf(std::uint32_t width, std::uint32_t height, PixelFormat format) {
  ImageFrame frame;
  frame.width = width;
  frame.height = height;
  frame.format = format;
  return frame;
}

std::size_t rawSize(std::uint32_t width, std::uint32_t height, PixelFormat format) {
  return std::size_t{width} * height * channelCount(format);
}

// Noise: incompressible.
std::vector<std::uint8_t> randomPixels(std::size_t bytes, std::mt19937& rng) {
  std::vector<std::uint8_t> raw(bytes);
  for (auto& b : raw) b = std::uint8_t(rng());
  return raw;
}

// A volume-like image: flat background with a few rows of detail.
std::vector<std::uint8_t> mostlyFlatPixels(std::uint32_t width, std::uint32_t height, PixelFormat format,
                                           std::mt19937& rng) {
  const std::size_t channels = channelCount(format);
  std::vector<std::uint8_t> raw(rawSize(width, height, format));
  for (std::size_t i = 0; i < raw.size(); ++i) raw[i] = std::uint8_t(i % channels == 3 ? 255 : 20 + i % channels);
  for (std::size_t y = height / 3; y < height / 3 + 2 && y < height; ++y)
    for (std::size_t x = 0; x < width / 2; ++x) raw[(y * width + x) * channels] = std::uint8_t(rng());
  return raw;
}

std::vector<std::uint8_t> requirePixels(const ImageFrame& frame) {
  auto decoded = decompressPixels(frame);
  if (const auto* error = std::get_if<ProtocolError>(&decoded)) FAIL("decompressPixels: " << error->text);
  return std::get<std::vector<std::uint8_t>>(decoded);
}

ProtocolError requireError(const ImageFrame& frame, const Limits& limits = {}) {
  auto decoded = decompressPixels(frame, limits);
  REQUIRE(std::holds_alternative<ProtocolError>(decoded));
  return std::get<ProtocolError>(decoded);
}

// A frame whose pixels are `bytes` as given, sent with `compression`.
ImageFrame withPixels(std::uint32_t width, std::uint32_t height, PixelFormat format, Compression compression,
                      std::vector<std::uint8_t> bytes) {
  ImageFrame frame = frameOf(width, height, format);
  frame.compression = compression;
  frame.pixels = std::move(bytes);
  return frame;
}

std::vector<std::uint8_t> zlibOf(const std::vector<std::uint8_t>& raw) {
  uLongf size = compressBound(uLong(raw.size()));
  std::vector<std::uint8_t> out(size);
  REQUIRE(compress2(out.data(), &size, raw.data(), uLong(raw.size()), 6) == Z_OK);
  out.resize(size);
  return out;
}

}  // namespace

TEST_CASE("pixel codec: every compression and format round-trips, falling back to none when it does not pay") {
  std::mt19937 rng(9);
  struct Shape {
    std::uint32_t width, height;
  };
  for (const Shape shape : {Shape{1, 1}, Shape{1, 1000}, Shape{1000, 1}, Shape{7, 5}, Shape{64, 48}, Shape{300, 2}}) {
    for (PixelFormat format : kFormats) {
      const std::size_t bytes = rawSize(shape.width, shape.height, format);
      std::vector<std::uint8_t> flat(bytes, 0);
      for (std::size_t i = 0; i < bytes; ++i) flat[i] = std::uint8_t(10 * (i % channelCount(format)) + 1);
      const std::vector<std::vector<std::uint8_t>> images{randomPixels(bytes, rng), flat,
                                                          mostlyFlatPixels(shape.width, shape.height, format, rng)};
      for (std::size_t kind = 0; kind < images.size(); ++kind) {
        for (Compression wanted : kCompressions) {
          DYNAMIC_SECTION(shape.width << " x " << shape.height << " " << int(format) << " image " << kind
                                      << " compression " << compressionName(wanted)) {
            const auto& raw = images[kind];
            ImageFrame frame = frameOf(shape.width, shape.height, format);
            setPixels(frame, raw, wanted);
            // The identity: decode(encode(raw)) == raw, byte for byte.
            CHECK(requirePixels(frame) == raw);
            // What was sent is the wanted compression exactly when it made the pixels fewer.
            const auto packed = compressPixels(raw, format, wanted);
            const bool pays = packed.size() < raw.size();
            CHECK(frame.compression == (pays ? wanted : Compression::kNone));
            CHECK(frame.pixels == (pays ? packed : raw));
            CHECK(frame.pixels.size() <= raw.size());
            // The frame passes the decoder and re-encodes to the same bytes.
            const auto bytesOnWire = encode(frame, 1);
            const auto decoded = decodeFrame(bytesOnWire);
            REQUIRE(std::holds_alternative<Decoded>(decoded));
            CHECK(std::get<ImageFrame>(std::get<Decoded>(decoded).message) == frame);
          }
        }
      }
    }
  }
}

TEST_CASE("pixel codec: flat images compress, noise and single pixels fall back to none") {
  std::mt19937 rng(1);
  for (PixelFormat format : kFormats) {
    const std::size_t channels = channelCount(format);
    // A flat 100 x 100 image is ceil(10000 / 256) = 40 runs of 1 + channels bytes.
    ImageFrame flat = frameOf(100, 100, format);
    setPixels(flat, std::vector<std::uint8_t>(rawSize(100, 100, format), 77), Compression::kRle);
    CHECK(flat.compression == Compression::kRle);
    CHECK(flat.pixels.size() == 40 * (1 + channels));
    ImageFrame zipped = frameOf(100, 100, format);
    setPixels(zipped, std::vector<std::uint8_t>(rawSize(100, 100, format), 77), Compression::kZlib);
    CHECK(zipped.compression == Compression::kZlib);
    CHECK(zipped.pixels.size() < rawSize(100, 100, format) / 100);

    // One pixel: a run is one byte longer than the pixel; zlib adds its header.
    for (Compression wanted : {Compression::kRle, Compression::kZlib}) {
      ImageFrame one = frameOf(1, 1, format);
      setPixels(one, std::vector<std::uint8_t>(channels, 5), wanted);
      CHECK(one.compression == Compression::kNone);
      CHECK(one.pixels == std::vector<std::uint8_t>(channels, 5));
      ImageFrame noise = frameOf(32, 32, format);
      setPixels(noise, randomPixels(rawSize(32, 32, format), rng), wanted);
      CHECK(noise.compression == Compression::kNone);
    }
  }
}

TEST_CASE("pixel codec: the RLE bytes are count-minus-one then the pixel, runs of at most 256 crossing rows") {
  // 2 x 2 RGB: a a / a b  -> run of 3 a, run of 1 b.
  const std::vector<std::uint8_t> raw{1, 2, 3, 1, 2, 3, 1, 2, 3, 9, 8, 7};
  CHECK(compressPixels(raw, PixelFormat::kRgb8, Compression::kRle) ==
        std::vector<std::uint8_t>{2, 1, 2, 3, 0, 9, 8, 7});
  // 257 equal RGBA pixels: a run of 256, then a run of 1.
  const std::vector<std::uint8_t> long_(257 * 4, 6);
  CHECK(compressPixels(long_, PixelFormat::kRgba8, Compression::kRle) ==
        std::vector<std::uint8_t>{255, 6, 6, 6, 6, 0, 6, 6, 6, 6});
  CHECK_THROWS_AS(compressPixels(std::vector<std::uint8_t>(5), PixelFormat::kRgb8, Compression::kRle),
                  std::invalid_argument);
  ImageFrame wrong = frameOf(2, 2, PixelFormat::kRgb8);
  CHECK_THROWS_AS(setPixels(wrong, std::vector<std::uint8_t>(11), Compression::kRle), std::invalid_argument);
}

TEST_CASE("pixel codec: damaged RLE is refused with what is wrong") {
  // 4 x 1 RGB = 12 raw bytes; the frame check wants fewer than 12 compressed.
  SECTION("a run cut short") {
    const auto e = requireError(withPixels(4, 1, PixelFormat::kRgb8, Compression::kRle, {3, 1, 2, 3, 0, 9}));
    CHECK(e.code == ErrorCode::kMalformedPayload);
    CHECK_THAT(e.text, Catch::Contains("6 bytes end inside a run") && Catch::Contains("the last one has 2"));
  }
  SECTION("a run past the end of the image") {
    const auto e = requireError(withPixels(4, 1, PixelFormat::kRgb8, Compression::kRle, {2, 1, 2, 3, 1, 9, 8, 7}));
    CHECK(e.code == ErrorCode::kMalformedPayload);
    CHECK_THAT(e.text, Catch::Contains("the run of 2 pixels at byte 4 runs past the end of the image, which has 1 "
                                       "pixels left"));
  }
  SECTION("runs that do not cover the image") {
    const auto e = requireError(withPixels(4, 1, PixelFormat::kRgb8, Compression::kRle, {1, 1, 2, 3}));
    CHECK(e.code == ErrorCode::kMalformedPayload);
    CHECK_THAT(e.text, Catch::Contains("the runs cover 2 of the image's 4 pixels"));
  }
  SECTION("no runs at all") {
    const auto e = requireError(withPixels(4, 1, PixelFormat::kRgb8, Compression::kRle, {}));
    CHECK_THAT(e.text, Catch::Contains("cover 0 of the image's 4 pixels"));
  }
  SECTION("the text names the frame") {
    const auto e = requireError(withPixels(4, 1, PixelFormat::kRgb8, Compression::kRle, {1, 1, 2, 3}));
    CHECK_THAT(e.text, Catch::StartsWith("ImageFrame 4 x 1 RGB8 pixels (RLE): "));
  }
}

TEST_CASE("pixel codec: damaged zlib is refused with what is wrong") {
  const std::vector<std::uint8_t> raw(64 * 64 * 4, 42);
  const auto good = zlibOf(raw);
  SECTION("garbage") {
    const auto e = requireError(withPixels(64, 64, PixelFormat::kRgba8, Compression::kZlib, std::vector<std::uint8_t>(64, 0x55)));
    CHECK(e.code == ErrorCode::kMalformedPayload);
    CHECK_THAT(e.text, Catch::Contains("zlib stream is damaged"));
  }
  SECTION("a stream cut short") {
    auto cut = good;
    cut.resize(cut.size() / 2);
    const auto e = requireError(withPixels(64, 64, PixelFormat::kRgba8, Compression::kZlib, cut));
    CHECK_THAT(e.text, Catch::Contains("the zlib stream ends after"));
  }
  SECTION("a stream of more bytes than the image") {
    const auto e = requireError(withPixels(64, 63, PixelFormat::kRgba8, Compression::kZlib, good));
    CHECK_THAT(e.text, Catch::Contains("inflates to more than the image's 16128 bytes"));
  }
  SECTION("a stream of fewer bytes than the image") {
    const auto e = requireError(withPixels(64, 65, PixelFormat::kRgba8, Compression::kZlib, good));
    CHECK_THAT(e.text, Catch::Contains("the zlib stream inflates to 16384 of 16640 bytes"));
  }
  SECTION("bytes after the end of the stream") {
    auto longer = good;
    longer.insert(longer.end(), {0, 0, 0});
    const auto e = requireError(withPixels(64, 64, PixelFormat::kRgba8, Compression::kZlib, longer));
    CHECK_THAT(e.text, Catch::Contains("3 bytes follow the end of the zlib stream"));
  }
  SECTION("a stream too short to inflate to the image at all") {
    const auto e = requireError(withPixels(4096, 4096, PixelFormat::kRgb8, Compression::kZlib, good));
    CHECK_THAT(e.text, Catch::Contains("a zlib stream of " + std::to_string(good.size()) +
                                       " bytes cannot inflate to the image's 50331648 bytes"));
  }
  CHECK(requirePixels(withPixels(64, 64, PixelFormat::kRgba8, Compression::kZlib, good)) == raw);
}

TEST_CASE("pixel codec: wrong sizes are refused by the frame's own check before decoding") {
  // Uncompressed pixels must be exactly width * height * channels bytes.
  auto e = requireError(withPixels(2, 2, PixelFormat::kRgba8, Compression::kNone, std::vector<std::uint8_t>(15)));
  CHECK(e.code == ErrorCode::kMalformedPayload);
  CHECK_THAT(e.text, Catch::Contains("needs 16 pixel bytes, got 15"));
  // Compressed pixels must be fewer.
  e = requireError(withPixels(2, 2, PixelFormat::kRgb8, Compression::kRle, std::vector<std::uint8_t>(12)));
  CHECK_THAT(e.text, Catch::Contains("not fewer than the 12 bytes"));
  // Empty and oversized images.
  e = requireError(withPixels(0, 2, PixelFormat::kRgb8, Compression::kRle, {}));
  CHECK(e.code == ErrorCode::kMalformedPayload);
  Limits small;
  small.maxImagePixels = 100;
  e = requireError(withPixels(11, 10, PixelFormat::kRgb8, Compression::kRle, {0, 1, 2, 3}), small);
  CHECK(e.code == ErrorCode::kLimitExceeded);
  CHECK_THAT(e.text, Catch::Contains("limit of 100 pixels"));
}
