// FrameRelay: frames pass through byte for byte after the decoder's checks;
// a frame refused whose end is known is skipped and the stream goes on.
#include <catch2/catch.hpp>

#include "hostile_frames.h"
#include "raw_frame.h"
#include "sample_messages.h"

using namespace pvr::proto;
using namespace pvr::proto::testing;

namespace {

struct Drained {
  std::vector<RelayedFrame> relayed;
  std::vector<RefusedFrame> refused;
  std::vector<int> order;  // 0 relayed, 1 refused, in pop order
};

Drained drain(FrameRelay& relay) {
  Drained out;
  while (auto item = relay.pop()) {
    if (auto* frame = std::get_if<RelayedFrame>(&*item)) {
      out.relayed.push_back(std::move(*frame));
      out.order.push_back(0);
    } else {
      out.refused.push_back(std::get<RefusedFrame>(std::move(*item)));
      out.order.push_back(1);
    }
  }
  return out;
}

void feedInChunks(FrameRelay& relay, std::span<const std::uint8_t> bytes, std::size_t chunk) {
  for (std::size_t at = 0; at < bytes.size(); at += chunk) relay.feed(bytes.subspan(at, std::min(chunk, bytes.size() - at)));
}

// A 2 x 1 RGB frame whose pixel byte count disagrees with its size.
std::vector<std::uint8_t> inconsistentImage(std::uint32_t requestId) {
  ImageFrame image{0, 2, 1, PixelFormat::kRgb8, Compression::kNone, {}, std::vector<std::uint8_t>(5, 1)};
  return encode(image, requestId, kFlagFinal);  // encode does not apply checks
}

}  // namespace

TEST_CASE("relay: every message type passes through byte for byte, however the bytes arrive") {
  std::vector<std::uint8_t> stream;
  std::vector<std::vector<std::uint8_t>> frames;
  const auto samples = sampleMessages();
  for (std::size_t i = 0; i < samples.size(); ++i) {
    frames.push_back(seedFrame(samples[i], i));
    stream.insert(stream.end(), frames.back().begin(), frames.back().end());
  }
  const std::size_t chunk = GENERATE(1, 3, 16, 17, 100, 100000);
  FrameRelay relay;
  feedInChunks(relay, stream, chunk);
  const Drained out = drain(relay);
  CHECK(out.refused.empty());
  REQUIRE(out.relayed.size() == samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    CHECK(out.relayed[i].bytes == frames[i]);
    CHECK(out.relayed[i].info == &messageInfo(samples[i]));
    CHECK(out.relayed[i].header == readHeader(std::span(frames[i]).first<kHeaderBytes>()));
  }
  CHECK(relay.bufferedBytes() == 0);
  CHECK_FALSE(relay.endOfStream().has_value());
}

TEST_CASE("relay: every hostile frame gets the decoder's verdict, word for word") {
  for (const HostileCase& hostile : hostileCases()) {
    DYNAMIC_SECTION(hostile.name) {
      const auto decoded = decodeFrame(hostile.bytes);
      REQUIRE(std::holds_alternative<ProtocolError>(decoded));
      const ProtocolError& expected = std::get<ProtocolError>(decoded);
      FrameRelay relay;
      relay.feed(hostile.bytes);
      const Drained out = drain(relay);
      CHECK(out.relayed.empty());
      const bool headerBroken = expected.code == ErrorCode::kBadMagic || expected.code == ErrorCode::kVersionMismatch ||
                                expected.code == ErrorCode::kUnknownType || expected.code == ErrorCode::kReservedFlags;
      if (headerBroken) {
        // The stream cannot be trusted after it: a final error.
        REQUIRE(relay.error().has_value());
        CHECK(*relay.error() == expected);
        CHECK(out.refused.empty());
      } else {
        // The frame's end is known: refused, and the stream goes on.
        CHECK_FALSE(relay.error().has_value());
        REQUIRE(out.refused.size() == 1);
        CHECK(out.refused[0].error == expected);
        CHECK(out.refused[0].header.requestId == 1);
      }
    }
  }
}

TEST_CASE("relay: a payload over its limit is skipped by its announced length, unbuffered, and the stream goes on") {
  // An ImageFrame one byte over the frame limit, then a good frame.
  const std::uint32_t over = kMaxFrameBytes - kHeaderBytes + 1;
  std::vector<std::uint8_t> stream = rawFrame({.type = ImageFrame::kWire.type, .requestId = 7, .payloadBytes = over},
                                              std::vector<std::uint8_t>(over, 0xAB));
  const auto good = encode(sampleMessages()[messageIndex<ImageFrame>()], 8, kFlagFinal);
  stream.insert(stream.end(), good.begin(), good.end());

  FrameRelay relay;
  relay.feed(std::span(stream).first(kHeaderBytes));
  // Refused as soon as the header is in, before any payload byte.
  auto first = relay.pop();
  REQUIRE(first);
  REQUIRE(std::holds_alternative<RefusedFrame>(*first));
  const auto& refused = std::get<RefusedFrame>(*first);
  CHECK(refused.error.code == ErrorCode::kFrameTooLarge);
  CHECK_THAT(refused.error.text, Catch::Contains("ImageFrame payload of " + std::to_string(over) +
                                                 " bytes exceeds the limit of " + std::to_string(over - 1)));
  CHECK(refused.header.requestId == 7);
  CHECK(refused.info == &messageInfo(ImageFrame{}));

  // The payload is dropped as it arrives: nothing is held for it.
  const auto rest = std::span(stream).subspan(kHeaderBytes);
  for (std::size_t at = 0; at < over; at += 1 << 20) {
    relay.feed(rest.subspan(at, std::min<std::size_t>(1 << 20, over - at)));
    CHECK(relay.bufferedBytes() == 0);
    CHECK_FALSE(relay.pop().has_value());
  }
  relay.feed(rest.subspan(over));
  const Drained out = drain(relay);
  CHECK(out.refused.empty());
  REQUIRE(out.relayed.size() == 1);
  CHECK(out.relayed[0].bytes == good);
  CHECK_FALSE(relay.error().has_value());
}

TEST_CASE("relay: an ImageFrame whose fixed fields disagree with its pixel count is refused, the next one relayed") {
  const std::uint32_t chunk = GENERATE(1u, 7u, 4096u);
  std::vector<std::uint8_t> stream = inconsistentImage(3);
  const auto good = encode(sampleMessages()[messageIndex<ImageFrame>()], 4, kFlagFinal);
  stream.insert(stream.end(), good.begin(), good.end());
  FrameRelay relay;
  feedInChunks(relay, stream, chunk);
  const Drained out = drain(relay);
  CHECK(out.order == std::vector<int>{1, 0});
  REQUIRE(out.refused.size() == 1);
  CHECK(out.refused[0].header.requestId == 3);
  CHECK(out.refused[0].header.flags == kFlagFinal);
  CHECK(out.refused[0].error.code == ErrorCode::kMalformedPayload);
  CHECK_THAT(out.refused[0].error.text, Catch::Contains("needs 6 pixel bytes, got 5"));
  REQUIRE(out.relayed.size() == 1);
  CHECK(out.relayed[0].bytes == good);
}

TEST_CASE("relay: tighter limits apply to image sizes as in the decoder") {
  Limits limits;
  limits.maxImagePixels = 4;
  const auto sample = sampleMessages()[messageIndex<ImageFrame>()];  // 4 x 3
  const auto bytes = encode(sample, 2);
  FrameRelay relay(limits);
  relay.feed(bytes);
  const Drained out = drain(relay);
  REQUIRE(out.refused.size() == 1);
  CHECK(out.refused[0].error == std::get<ProtocolError>(decodeFrame(bytes, limits)));
  CHECK(out.refused[0].error.code == ErrorCode::kLimitExceeded);
}

TEST_CASE("relay: the stream ending inside a frame, or inside a skipped payload, is a truncated frame") {
  const auto frame = encode(Hello{"cut"}, 1);
  FrameRelay inside;
  inside.feed(std::span(frame).first(frame.size() - 1));
  CHECK(inside.bufferedBytes() == frame.size() - 1);
  REQUIRE(inside.endOfStream().has_value());
  CHECK(inside.error()->code == ErrorCode::kTruncatedFrame);
  CHECK_THAT(inside.error()->text, Catch::Contains(std::to_string(frame.size() - 1) + " bytes into a frame"));

  FrameRelay skipping;
  skipping.feed(rawFrame({.type = Hello::kWire.type, .payloadBytes = 0xFFFFFFFF}, std::vector<std::uint8_t>(10)));
  REQUIRE(skipping.pop().has_value());
  REQUIRE(skipping.endOfStream().has_value());
  CHECK(skipping.error()->code == ErrorCode::kTruncatedFrame);
  CHECK_THAT(skipping.error()->text, Catch::Contains("4294967285 bytes before the end of a refused frame"));

  FrameRelay clean;
  clean.feed(frame);
  CHECK(clean.pop().has_value());
  CHECK_FALSE(clean.endOfStream().has_value());
}

TEST_CASE("relay: after a broken header nothing more is relayed") {
  auto stream = encode(Ok{}, 1);
  stream.push_back('G');  // not the magic
  const auto later = encode(Ok{}, 2);
  stream.insert(stream.end(), later.begin(), later.end());
  FrameRelay relay;
  relay.feed(stream);
  relay.feed(later);
  const Drained out = drain(relay);
  CHECK(out.relayed.size() == 1);
  REQUIRE(relay.error().has_value());
  CHECK(relay.error()->code == ErrorCode::kBadMagic);
}
