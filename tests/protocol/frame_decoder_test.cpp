// FrameDecoder: holds at most one unfinished frame, delivers what decoded
// before an error, and stops at the first error.
#include <catch2/catch.hpp>

#include "raw_frame.h"
#include "sample_messages.h"

using namespace pvr::proto;
using namespace pvr::proto::testing;

TEST_CASE("FrameDecoder never holds more than the unfinished frame") {
  ImageFrame image{1, 64, 64, PixelFormat::kRgba8, Compression::kNone, {}, std::vector<std::uint8_t>(64 * 64 * 4, 3)};
  const auto frame = encode(image, 5);
  const auto hello = encode(Hello{"x"}, 6);
  std::vector<std::uint8_t> stream = frame;
  stream.insert(stream.end(), hello.begin(), hello.end());

  FrameDecoder decoder;
  const std::size_t chunk = 1000;
  std::size_t delivered = 0;
  for (std::size_t at = 0; at < stream.size(); at += chunk) {
    decoder.feed(std::span(stream).subspan(at, std::min(chunk, stream.size() - at)));
    // Identity checked: buffered = bytes fed - bytes of frames already decoded.
    const std::size_t fed = std::min(at + chunk, stream.size());
    while (auto got = decoder.pop()) delivered += got->bytesConsumed;
    CHECK(decoder.bufferedBytes() == fed - delivered);
    CHECK(decoder.bufferedBytes() < frame.size());
  }
  CHECK(delivered == stream.size());
}

TEST_CASE("messages decoded before an error are delivered and input after it is dropped") {
  auto stream = encode(Hello{"a"}, 1);
  const auto ok = encode(Ok{}, 2);
  stream.insert(stream.end(), ok.begin(), ok.end());
  stream.insert(stream.end(), {'G', 'E', 'T'});
  const auto close = encode(Close{"late"}, 3);
  stream.insert(stream.end(), close.begin(), close.end());

  FrameDecoder decoder;
  decoder.feed(stream);
  REQUIRE(decoder.error().has_value());
  CHECK(decoder.error()->code == ErrorCode::kBadMagic);
  auto first = decoder.pop();
  auto second = decoder.pop();
  REQUIRE(first.has_value());
  REQUIRE(second.has_value());
  CHECK(std::holds_alternative<Hello>(first->message));
  CHECK(std::holds_alternative<Ok>(second->message));
  CHECK_FALSE(decoder.pop().has_value());

  // A dead decoder ignores everything, even valid frames.
  decoder.feed(encode(Ok{}, 4));
  CHECK_FALSE(decoder.pop().has_value());
  CHECK(decoder.bufferedBytes() == 0);
  CHECK(decoder.endOfStream()->code == ErrorCode::kBadMagic);
}

TEST_CASE("end of stream between frames is clean, inside one is truncation") {
  FrameDecoder clean;
  clean.feed(encode(Ok{}, 1));
  CHECK_FALSE(clean.endOfStream().has_value());

  FrameDecoder cut;
  const auto frame = encode(CatalogReply{{{"a", 1}, {"b", 1}}}, 1);
  cut.feed(std::span(frame).first(frame.size() - 1));
  REQUIRE(cut.endOfStream().has_value());
  CHECK(cut.error()->code == ErrorCode::kTruncatedFrame);
}

TEST_CASE("an empty feed changes nothing") {
  FrameDecoder decoder;
  decoder.feed({});
  CHECK(decoder.bufferedBytes() == 0);
  CHECK_FALSE(decoder.error().has_value());
  CHECK_FALSE(decoder.pop().has_value());
}

TEST_CASE("FrameDecoder applies its own limits") {
  Limits limits;
  limits.maxTextPayload = 16;
  FrameDecoder decoder(limits);
  decoder.feed(encode(SetScene{"brain.slc", R"({"image":{"width":64}})"}, 1));
  REQUIRE(decoder.error().has_value());
  CHECK(decoder.error()->code == ErrorCode::kFrameTooLarge);
}
