// Hostile input: every malformed frame is an error with a stable code and a
// clear text, never a crash, never a wait for bytes that cannot be valid.
#include <catch2/catch.hpp>

#include <limits>
#include <string>

#include "hostile_frames.h"
#include "raw_frame.h"
#include "sample_messages.h"

using namespace pvr::proto;
using namespace pvr::proto::testing;

TEST_CASE("hostile frames are refused with a stable code and a clear text") {
  for (const HostileCase& hostile : hostileCases()) {
    DYNAMIC_SECTION(hostile.name) {
      const DecodeResult result = decodeFrame(hostile.bytes);
      REQUIRE(std::holds_alternative<ProtocolError>(result));
      const auto& error = std::get<ProtocolError>(result);
      CHECK(error.code == hostile.code);
      CHECK_THAT(error.text, Catch::Contains(hostile.textContains));

      // The incremental decoder agrees, fed whole or a byte at a time.
      FrameDecoder whole;
      whole.feed(hostile.bytes);
      REQUIRE(whole.error().has_value());
      CHECK(*whole.error() == error);
      FrameDecoder trickle;
      for (std::size_t i = 0; i < hostile.bytes.size() && !trickle.error(); ++i) {
        trickle.feed(std::span(hostile.bytes).subspan(i, 1));
      }
      REQUIRE(trickle.error().has_value());
      CHECK(trickle.error()->code == hostile.code);
      CHECK_FALSE(trickle.pop().has_value());
    }
  }
}

TEST_CASE("a wrong magic is refused at its first wrong byte") {
  // 'G' of "GET" is wrong at byte 0: no need to wait for a whole header.
  const std::vector<std::uint8_t> one{'G'};
  const auto result = decodeFrame(one);
  REQUIRE(std::holds_alternative<ProtocolError>(result));
  CHECK(std::get<ProtocolError>(result).code == ErrorCode::kBadMagic);
  // A correct prefix of the magic is only incomplete.
  CHECK(std::holds_alternative<NeedMore>(decodeFrame(std::span(kMagic).first(3))));
}

TEST_CASE("a valid header arriving a byte at a time is NeedMore until complete") {
  const auto frame = encode(Hello{"pvrsh 0.1"}, 9);
  for (std::size_t n = 0; n < kHeaderBytes; ++n) {
    const auto result = decodeFrame(std::span(frame).first(n));
    REQUIRE(std::holds_alternative<NeedMore>(result));
    CHECK(std::get<NeedMore>(result).frameBytes == kHeaderBytes);
  }
  // With the header complete, the frame size is known.
  const auto result = decodeFrame(std::span(frame).first(kHeaderBytes));
  REQUIRE(std::holds_alternative<NeedMore>(result));
  CHECK(std::get<NeedMore>(result).frameBytes == frame.size());
}

TEST_CASE("every truncation of every valid frame is NeedMore, then a truncated-frame error at end of stream") {
  for (const Message& message : sampleMessages()) {
    DYNAMIC_SECTION(messageInfo(message).name) {
      const auto frame = encode(message, 3);
      for (std::size_t n = 1; n < frame.size(); ++n) {
        const auto prefix = std::span(frame).first(n);
        REQUIRE(std::holds_alternative<NeedMore>(decodeFrame(prefix)));
        FrameDecoder decoder;
        decoder.feed(prefix);
        CHECK(decoder.bufferedBytes() == n);
        const auto& error = decoder.endOfStream();
        REQUIRE(error.has_value());
        CHECK(error->code == ErrorCode::kTruncatedFrame);
        CHECK_THAT(error->text, Catch::Contains(std::to_string(n) + " bytes into a frame"));
      }
    }
  }
}

TEST_CASE("a frame announcing 4 GiB fails right after its header, with nothing buffered") {
  const auto header = rawFrame({.type = ImageFrame::kWire.type, .payloadBytes = 0xFFFFFFFF}, {});
  FrameDecoder decoder;
  decoder.feed(std::span(header).first(kHeaderBytes - 1));
  CHECK_FALSE(decoder.error().has_value());
  CHECK(decoder.bufferedBytes() == kHeaderBytes - 1);
  decoder.feed(std::span(header).last(1));
  REQUIRE(decoder.error().has_value());
  CHECK(decoder.error()->code == ErrorCode::kFrameTooLarge);
  CHECK(decoder.bufferedBytes() == 0);
}

TEST_CASE("tighter limits from the caller are enforced") {
  Limits limits;
  limits.maxControlPayload = 8;
  limits.maxImagePixels = 4;
  const auto hello = encode(Hello{"123456789"}, 1);  // 13-byte payload
  auto result = decodeFrame(hello, limits);
  REQUIRE(std::holds_alternative<ProtocolError>(result));
  CHECK(std::get<ProtocolError>(result).code == ErrorCode::kFrameTooLarge);

  const auto image = encode(ImageFrame{0, 3, 2, PixelFormat::kRgb8, Compression::kNone, {},
                                       std::vector<std::uint8_t>(18)},
                            1);
  result = decodeFrame(image, limits);
  REQUIRE(std::holds_alternative<ProtocolError>(result));
  CHECK(std::get<ProtocolError>(result).code == ErrorCode::kLimitExceeded);
  CHECK(std::holds_alternative<Decoded>(decodeFrame(image)));
}
