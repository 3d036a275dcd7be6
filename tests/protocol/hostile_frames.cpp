// The hostile frames shared by the decoder and relay tests.
#include "hostile_frames.h"

#include <initializer_list>
#include <string>

#include "raw_frame.h"

namespace pvr::proto::testing {
namespace {

std::vector<std::uint8_t> u32(std::uint32_t v) {
  return payload([&](ByteWriter& w) { w.integer(v); });
}

// A Hello payload whose string length field says `length`, followed by `text`.
std::vector<std::uint8_t> helloWithLength(std::uint32_t length, const char* text) {
  auto bytes = u32(length);
  const auto body = textBytes(text);
  bytes.insert(bytes.end(), body.begin(), body.end());
  return bytes;
}

std::vector<std::uint8_t> imagePayload(std::uint32_t width, std::uint32_t height, std::uint8_t format,
                                       std::uint8_t compression, std::size_t pixelBytes) {
  return payload([&](ByteWriter& w) {
    w.integer<std::uint32_t>(0);
    w.integer(width);
    w.integer(height);
    w.integer(format);
    w.integer(compression);
    for (std::size_t i = 0; i < sizeof(FrameTiming) / sizeof(double); ++i) w.f64(0.0);  // every phase
    w.lengthPrefixed(std::vector<std::uint8_t>(pixelBytes, 0x55));
  });
}

std::vector<std::uint8_t> withByte(std::vector<std::uint8_t> bytes, std::size_t at, std::uint8_t value) {
  bytes[at] = value;
  return bytes;
}

std::vector<std::uint8_t> appended(std::vector<std::uint8_t> bytes, std::initializer_list<std::uint8_t> extra) {
  bytes.insert(bytes.end(), extra);
  return bytes;
}

}  // namespace

std::vector<HostileCase> hostileCases() {
  const auto validHello = encode(Hello{"pvrsh"}, 1);
  const std::uint8_t helloType = Hello::kWire.type;
  const std::uint8_t imageType = ImageFrame::kWire.type;
  const std::uint8_t sessionType = SessionOpen::kWire.type;
  const Limits limits;
  return {
      // Header.
      {"an HTTP request instead of a frame", textBytes("GET / HTTP/1.1\r\n\r\n"), ErrorCode::kBadMagic, "bad magic"},
      {"last magic byte wrong", withByte(validHello, 3, 'X'), ErrorCode::kBadMagic, "89 50 56 58"},
      {"version 2", withByte(validHello, 4, 2), ErrorCode::kVersionMismatch, "version 2"},
      {"version 0", withByte(validHello, 4, 0), ErrorCode::kVersionMismatch, "this build speaks 1"},
      {"type 0", withByte(validHello, 5, 0), ErrorCode::kUnknownType, "0x00"},
      {"type 0x7f", withByte(validHello, 5, 0x7F), ErrorCode::kUnknownType, "0x7f"},
      {"type 0xff", withByte(validHello, 5, 0xFF), ErrorCode::kUnknownType, "0xff"},
      {"reserved flag bit 1", withByte(validHello, 6, 0x02), ErrorCode::kReservedFlags, "0x0002"},
      {"reserved flag bit 15", withByte(validHello, 7, 0x80), ErrorCode::kReservedFlags, "0x8000"},
      {"Hello announcing 0xFFFFFFFF bytes", rawFrame({.type = helloType, .payloadBytes = 0xFFFFFFFF}, {}),
       ErrorCode::kFrameTooLarge, "4294967295"},
      {"ImageFrame announcing 0xFFFFFFFF bytes", rawFrame({.type = imageType, .payloadBytes = 0xFFFFFFFF}, {}),
       ErrorCode::kFrameTooLarge, "ImageFrame payload of 4294967295 bytes"},
      {"ImageFrame one byte over the frame limit",
       rawFrame({.type = imageType, .payloadBytes = kMaxFrameBytes - kHeaderBytes + 1}, {}),
       ErrorCode::kFrameTooLarge, "exceeds the limit"},
      {"control message one byte over its limit",
       rawFrame({.type = helloType, .payloadBytes = limits.maxControlPayload + 1}, {}), ErrorCode::kFrameTooLarge,
       std::to_string(limits.maxControlPayload)},
      {"SetScene over the text limit",
       rawFrame({.type = SetScene::kWire.type, .payloadBytes = limits.maxTextPayload + 1}, {}),
       ErrorCode::kFrameTooLarge, "SetScene"},

      // Lengths inside payloads.
      {"string length 0xFFFFFFFF", rawFrame({}, helloWithLength(0xFFFFFFFF, "pvrsh")), ErrorCode::kMalformedPayload,
       "length 4294967295"},
      {"string length 0x80000000 (negative as int32)", rawFrame({}, helloWithLength(0x80000000, "pvrsh")),
       ErrorCode::kMalformedPayload, "only 5 are left"},
      {"string length one too long", rawFrame({}, helloWithLength(6, "pvrsh")), ErrorCode::kMalformedPayload,
       "string length 6"},
      {"string length one too short", rawFrame({}, helloWithLength(4, "pvrsh")), ErrorCode::kMalformedPayload,
       "1 trailing bytes"},
      {"string length field cut short", rawFrame({}, {5, 0}), ErrorCode::kMalformedPayload, "runs past the end"},
      {"list count larger than the payload",
       rawFrame({.type = sessionType}, payload([](ByteWriter& w) {
                  w.integer<std::uint32_t>(4);
                  w.integer<std::uint32_t>(0x7FFFFFFF);
                })),
       ErrorCode::kMalformedPayload, "list length 2147483647"},
      {"list count one too many",
       rawFrame({.type = sessionType}, payload([](ByteWriter& w) {
                  w.integer<std::uint32_t>(4);
                  w.integer<std::uint32_t>(2);
                  w.integer<std::uint8_t>(0);
                  w.integer<std::uint32_t>(16);
                  w.integer<std::uint32_t>(0);
                })),
       ErrorCode::kMalformedPayload, "list length 2"},
      {"byte array longer than the payload", rawFrame({.type = imageType}, [] {
         auto bytes = imagePayload(1, 1, 0, 0, 3);
         bytes[bytes.size() - 7] = 4;  // pixel count 3 -> 4
         return bytes;
       }()),
       ErrorCode::kMalformedPayload, "byte array length 4"},

      // Payload contents.
      {"trailing garbage after an empty payload", rawFrame({.type = Ok::kWire.type}, {0}),
       ErrorCode::kMalformedPayload, "Ok payload: 1 trailing bytes"},
      {"trailing garbage after a valid Hello",
       rawFrame({}, appended(payload([](ByteWriter& w) { w.lengthPrefixed(textBytes("pvrsh")); }), {0xDE, 0xAD})),
       ErrorCode::kMalformedPayload, "2 trailing bytes"},
      {"fixed-size payload cut short", rawFrame({.type = Cancel::kWire.type}, {1, 2, 3}),
       ErrorCode::kMalformedPayload, "Cancel payload"},
      {"nonce one byte short", rawFrame({.type = AuthChallenge::kWire.type}, std::vector<std::uint8_t>(31, 7)),
       ErrorCode::kMalformedPayload, "AuthChallenge payload"},
      {"MAC one byte long", rawFrame({.type = AuthResponse::kWire.type}, std::vector<std::uint8_t>(33, 7)),
       ErrorCode::kMalformedPayload, "1 trailing bytes"},
      {"boolean 2", rawFrame({.type = Welcome::kWire.type}, {0, 0, 0, 0, 0, 0, 0, 0, 2}),
       ErrorCode::kMalformedPayload, "not 0 or 1"},
      {"cluster role 4",
       rawFrame({.type = SetLayout::kWire.type}, {1, 0, 0, 0, 4, 1, 0, 0, 0, 0, 0, 0, 0}),
       ErrorCode::kMalformedPayload, "enumeration value 4"},
      {"pixel format 2", rawFrame({.type = imageType}, imagePayload(1, 1, 2, 0, 3)), ErrorCode::kMalformedPayload,
       "enumeration value 2"},
      {"compression 3", rawFrame({.type = imageType}, imagePayload(1, 1, 0, 3, 3)), ErrorCode::kMalformedPayload,
       "enumeration value 3"},
      {"performance query 3", rawFrame({.type = PerformanceRequest::kWire.type}, {3, 0, 0, 0, 0}),
       ErrorCode::kMalformedPayload, "enumeration value 3"},
      {"uncompressed image one pixel byte short", rawFrame({.type = imageType}, imagePayload(2, 2, 0, 0, 11)),
       ErrorCode::kMalformedPayload, "needs 12 pixel bytes, got 11"},
      {"uncompressed image one pixel byte long", rawFrame({.type = imageType}, imagePayload(2, 2, 1, 0, 17)),
       ErrorCode::kMalformedPayload, "needs 16 pixel bytes, got 17"},
      {"image of zero width", rawFrame({.type = imageType}, imagePayload(0, 5, 0, 1, 0)),
       ErrorCode::kMalformedPayload, "0 x 5"},
      {"image of 2^32-1 x 2^32-1 pixels", rawFrame({.type = imageType}, imagePayload(0xFFFFFFFF, 0xFFFFFFFF, 0, 2, 8)),
       ErrorCode::kLimitExceeded, "exceeds the protocol's limit of"},
      {"RLE pixels as many as the uncompressed ones", rawFrame({.type = imageType}, imagePayload(2, 2, 0, 1, 12)),
       ErrorCode::kMalformedPayload, "RLE pixels of 12 bytes are not fewer than the 12 bytes"},
      {"zlib pixels more than the uncompressed ones", rawFrame({.type = imageType}, imagePayload(1, 1, 1, 2, 11)),
       ErrorCode::kMalformedPayload, "zlib pixels of 11 bytes are not fewer than the 4 bytes"},

      // Rotation requests (RenderRotation::check).
      {"rotation of 0 steps per turn", encode(RenderRotation{{0, 1, 0}, 0, 3, 0}, 1), ErrorCode::kBadArgument,
       "0 steps per turn"},
      {"rotation ending before it starts", encode(RenderRotation{{0, 1, 0}, 5, 4, 60}, 1), ErrorCode::kBadArgument,
       "the end step is below the start step"},
      {"rotation of one frame too many", encode(RenderRotation{{0, 1, 0}, 1, std::int32_t(kMaxRotationFrames) + 1, 60}, 1),
       ErrorCode::kLimitExceeded, "limit of " + std::to_string(kMaxRotationFrames) + " frames"},
      {"rotation about the zero axis", encode(RenderRotation{{0, 0, 0}, 0, 1, 60}, 1), ErrorCode::kBadArgument,
       "not a finite nonzero vector"},
      // Interactive requests (RenderInteractive::check).
      {"interactive render without reduction", encode(RenderInteractive{1, {0, 0, 1}, 0, 1}, 1),
       ErrorCode::kBadArgument, "reduction 1"},
      {"interactive render turning about a zero axis", encode(RenderInteractive{4, {0, 0, 0}, 3, 60}, 1),
       ErrorCode::kBadArgument, "not a finite nonzero vector"},
      // Time-step requests (RenderTimeSteps::check).
      {"time steps with stride 0", encode(RenderTimeSteps{0, 9, 0}, 1), ErrorCode::kBadArgument, "stride 0"},
      {"time steps ending before they start", encode(RenderTimeSteps{5, 4, 1}, 1), ErrorCode::kBadArgument,
       "the last step is below the first"},
      {"time steps of one frame too many", encode(RenderTimeSteps{0, kMaxRotationFrames, 1}, 1),
       ErrorCode::kLimitExceeded, "limit of " + std::to_string(kMaxRotationFrames) + " frames"},
      // A computation's steps (RenderSteps::check).
      {"computed steps of 0 steps", encode(RenderSteps{0, 1}, 1), ErrorCode::kBadArgument, "the steps must be at least 1"},
      {"computed steps every 0", encode(RenderSteps{5, 0}, 1), ErrorCode::kBadArgument, "every must be at least 1"},
      {"computed steps of one frame too many", encode(RenderSteps{kMaxRotationFrames + 1, 1}, 1),
       ErrorCode::kLimitExceeded, "limit of " + std::to_string(kMaxRotationFrames) + " frames"},
  };
}

}  // namespace pvr::proto::testing
