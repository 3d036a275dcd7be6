// Every message type survives encode -> decode unchanged, whether the frame
// arrives whole, a byte at a time, or packed with others in one buffer.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <limits>

#include "sample_messages.h"

using namespace pvr::proto;
using pvr::proto::testing::sampleMessages;

namespace {

Decoded requireDecoded(DecodeResult result) {
  if (const auto* error = std::get_if<ProtocolError>(&result)) FAIL("decode error: " << error->text);
  REQUIRE(std::holds_alternative<Decoded>(result));
  return std::move(std::get<Decoded>(result));
}

std::vector<Decoded> drain(FrameDecoder& decoder) {
  std::vector<Decoded> out;
  while (auto frame = decoder.pop()) out.push_back(std::move(*frame));
  return out;
}

}  // namespace

TEST_CASE("every message type round-trips through encode and decodeFrame") {
  const auto samples = sampleMessages();
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const Message& message = samples[i];
    DYNAMIC_SECTION(messageInfo(message).name) {
      const std::uint32_t requestId = 1000 + static_cast<std::uint32_t>(i);
      const auto frame = encode(message, requestId, kFlagFinal);
      const Decoded decoded = requireDecoded(decodeFrame(frame));
      CHECK(decoded.message == message);
      CHECK(decoded.info.requestId == requestId);
      CHECK(decoded.info.final());
      CHECK(decoded.bytesConsumed == frame.size());
      // The payload length in the header is the frame minus its header.
      CHECK(readHeader(std::span(frame).first<kHeaderBytes>()).payloadBytes == frame.size() - kHeaderBytes);
    }
  }
}

TEST_CASE("every message type decodes when fed to FrameDecoder one byte at a time") {
  for (const Message& message : sampleMessages()) {
    DYNAMIC_SECTION(messageInfo(message).name) {
      const auto frame = encode(message, 7);
      FrameDecoder decoder;
      for (std::size_t i = 0; i < frame.size(); ++i) {
        // Nothing comes out before the last byte, and never an error.
        REQUIRE_FALSE(decoder.pop().has_value());
        decoder.feed(std::span(frame).subspan(i, 1));
        REQUIRE_FALSE(decoder.error().has_value());
      }
      auto decoded = decoder.pop();
      REQUIRE(decoded.has_value());
      CHECK(decoded->message == message);
      CHECK(decoded->info.requestId == 7);
      CHECK(decoder.bufferedBytes() == 0);
      CHECK_FALSE(decoder.endOfStream().has_value());
    }
  }
}

TEST_CASE("two frames in one buffer decode in order, each consuming only its own bytes") {
  const auto samples = sampleMessages();
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const Message& first = samples[i];
    const Message& second = samples[(i + 1) % samples.size()];
    DYNAMIC_SECTION(messageInfo(first).name << " then " << messageInfo(second).name) {
      auto buffer = encode(first, 1);
      const std::size_t firstBytes = buffer.size();
      const auto tail = encode(second, 2);
      buffer.insert(buffer.end(), tail.begin(), tail.end());

      const Decoded a = requireDecoded(decodeFrame(buffer));
      CHECK(a.message == first);
      CHECK(a.bytesConsumed == firstBytes);
      const Decoded b = requireDecoded(decodeFrame(std::span(buffer).subspan(a.bytesConsumed)));
      CHECK(b.message == second);
      CHECK(b.info.requestId == 2);

      FrameDecoder decoder;
      decoder.feed(buffer);
      auto both = drain(decoder);
      REQUIRE(both.size() == 2);
      CHECK(both[0].message == first);
      CHECK(both[1].message == second);
    }
  }
}

TEST_CASE("a stream of every message type survives any chunking") {
  std::vector<std::uint8_t> stream;
  const auto samples = sampleMessages();
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const auto frame = encode(samples[i], static_cast<std::uint32_t>(i));
    stream.insert(stream.end(), frame.begin(), frame.end());
  }
  const std::size_t chunk = GENERATE(1, 2, 3, 7, 15, 16, 17, 64, 1000, 100000);
  FrameDecoder decoder;
  for (std::size_t at = 0; at < stream.size(); at += chunk) {
    decoder.feed(std::span(stream).subspan(at, std::min(chunk, stream.size() - at)));
  }
  const auto decoded = drain(decoder);
  REQUIRE(decoded.size() == samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    CHECK(decoded[i].message == samples[i]);
    CHECK(decoded[i].info.requestId == i);
  }
  CHECK_FALSE(decoder.endOfStream().has_value());
}

TEST_CASE("extreme field values round-trip bit for bit") {
  // The widest rotation RenderRotation::check allows, about an axis of a
  // negative zero, a huge and a subnormal component.
  constexpr std::int32_t kLast = std::numeric_limits<std::int32_t>::max();
  RenderRotation rotation{{-0.0, 1e308, std::numeric_limits<double>::denorm_min()},
                          kLast - std::int32_t(kMaxRotationFrames) + 1, kLast,
                          std::numeric_limits<std::uint32_t>::max()};
  const auto frame = encode(rotation, std::numeric_limits<std::uint32_t>::max());
  const Decoded decoded = requireDecoded(decodeFrame(frame));
  const auto& back = std::get<RenderRotation>(decoded.message);
  // -0.0 == 0.0, so compare the bit patterns and re-encode.
  CHECK(std::memcmp(back.axis.data(), rotation.axis.data(), sizeof rotation.axis) == 0);
  CHECK(back.start == rotation.start);
  CHECK(back.end == rotation.end);
  CHECK(back.stepsPerTurn == rotation.stepsPerTurn);
  CHECK(decoded.info.requestId == std::numeric_limits<std::uint32_t>::max());
  CHECK(encode(back, decoded.info.requestId) == frame);
}

TEST_CASE("empty strings, lists and unknown error codes round-trip") {
  const std::vector<Message> messages{
      Hello{""}, SetScene{"", ""}, SessionOpen{0, {}, ""}, StatusReply{{{"", ""}}}, CatalogReply{{}},
      // A code from a newer peer passes through unchanged.
      ErrorMessage{static_cast<ErrorCode>(999), "from the future"},
      ImageFrame{0, 1, 1, PixelFormat::kRgba8, Compression::kZlib, {}, {}}};
  for (const Message& message : messages) {
    const Decoded decoded = requireDecoded(decodeFrame(encode(message, 0)));
    CHECK(decoded.message == message);
  }
}

TEST_CASE("encode refuses reserved flag bits") {
  CHECK_THROWS_AS(encode(Ok{}, 1, 0x0002), std::invalid_argument);
  CHECK_NOTHROW(encode(Ok{}, 1, kFlagFinal));
}
