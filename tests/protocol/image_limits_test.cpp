// The one rule for image sizes (protocol/image_limits.h).
#include <catch2/catch.hpp>

#include "pvr_protocol.h"

using namespace pvr::proto;

TEST_CASE("image limits: sizes that fit one frame pass, larger ones name the limit", "[limits]") {
  CHECK_FALSE(checkImageSize(512, 512, PixelFormat::kRgba8));
  CHECK_FALSE(checkImageSize(4096, 4096, PixelFormat::kRgb8));  // 48 MiB of pixels
  const auto rgba = checkImageSize(4096, 4096, PixelFormat::kRgba8);  // 64 MiB of pixels + fields
  REQUIRE(rgba);
  CHECK(rgba->code == ErrorCode::kLimitExceeded);
  CHECK_THAT(rgba->text, Catch::Contains("bytes per frame"));
  const auto huge = checkImageSize(16384, 16384, PixelFormat::kRgb8);
  REQUIRE(huge);
  CHECK_THAT(huge->text, Catch::Contains("67108864 pixels"));
  CHECK(checkImageSize(0, 10, PixelFormat::kRgb8)->code == ErrorCode::kBadArgument);
  CHECK(checkImageSize(1ull << 40, 1ull << 40, PixelFormat::kRgb8)->code == ErrorCode::kLimitExceeded);
}

TEST_CASE("image limits: the largest image that passes encodes into a frame the decoder accepts", "[limits]") {
  // The widest RGB8 image with 2048 rows under the frame limit.
  const Limits limits;
  std::uint32_t width = 1;
  while (!checkImageSize(width * 2, 2048, PixelFormat::kRgb8)) width *= 2;
  while (!checkImageSize(width + 256, 2048, PixelFormat::kRgb8)) width += 256;
  ImageFrame f;
  f.width = width;
  f.height = 2048;
  f.format = PixelFormat::kRgb8;
  f.pixels.assign(std::size_t(width) * 2048 * 3, 7);
  const auto bytes = encode(f, 1, kFlagFinal);
  CHECK(bytes.size() - kHeaderBytes == imageFramePayloadBytes(width, 2048, PixelFormat::kRgb8));
  CHECK(bytes.size() - kHeaderBytes <= limits.maxFrameBytes);
  FrameDecoder decoder;
  decoder.feed(bytes);
  const auto decoded = decoder.pop();
  REQUIRE(decoded);
  CHECK(std::get<ImageFrame>(decoded->message).width == width);
}
