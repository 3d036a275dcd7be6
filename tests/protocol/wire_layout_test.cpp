// The bytes on the wire are exactly those docs/protocol.md specifies; a
// change here is a protocol change and needs a new kProtocolVersion.
#include <catch2/catch.hpp>

#include "byte_io.h"
#include "pvr_protocol.h"

using namespace pvr::proto;

TEST_CASE("the header is magic, version, type, flags, request id, payload length, little-endian") {
  const auto frame = encode(Cancel{0x0A0B0C0D}, 0x11223344, kFlagFinal);
  const std::vector<std::uint8_t> expected{
      0x89, 'P',  'V',  'R',   // magic
      0x01,                    // version
      0x23,                    // type: Cancel
      0x01, 0x00,              // flags: final
      0x44, 0x33, 0x22, 0x11,  // request id
      0x04, 0x00, 0x00, 0x00,  // payload length
      0x0D, 0x0C, 0x0B, 0x0A,  // Cancel.target
  };
  CHECK(frame == expected);
}

TEST_CASE("strings are a u32 byte count then the bytes and booleans one byte") {
  const auto frame = encode(Welcome{"ab", 3, true}, 0);
  const std::vector<std::uint8_t> payload(frame.begin() + kHeaderBytes, frame.end());
  const std::vector<std::uint8_t> expected{2, 0, 0, 0, 'a', 'b', 3, 0, 0, 0, 1};
  CHECK(payload == expected);
}

TEST_CASE("an ImageFrame payload follows the documented field order") {
  ImageFrame image{5, 1, 2, PixelFormat::kRgba8, Compression::kRle, {1.0, 0, 0, 0, 0, 0, 0.5}, {9, 8, 7}};
  const auto frame = encode(image, 0);
  std::vector<std::uint8_t> expected;
  ByteWriter w(expected);
  w.integer<std::uint32_t>(5);  // frame number
  w.integer<std::uint32_t>(1);  // width
  w.integer<std::uint32_t>(2);  // height
  w.integer<std::uint8_t>(1);   // RGBA
  w.integer<std::uint8_t>(1);   // RLE
  for (double t : {1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.5}) w.f64(t);  // read .. send
  w.integer<std::uint32_t>(3);  // pixel byte count
  w.raw(std::vector<std::uint8_t>{9, 8, 7});
  CHECK(std::vector<std::uint8_t>(frame.begin() + kHeaderBytes, frame.end()) == expected);
  // 1.0 is 0x3FF0000000000000, stored low byte first.
  CHECK(expected[14] == 0x00);
  CHECK(expected[21] == 0x3F);
  CHECK(expected[20] == 0xF0);
}

TEST_CASE("ByteReader failures are sticky and name the offset") {
  const std::vector<std::uint8_t> bytes{1, 2, 3};
  ByteReader reader(bytes, "test payload");
  CHECK(reader.integer<std::uint16_t>() == 0x0201);
  CHECK(reader.integer<std::uint32_t>() == 0);  // past the end
  REQUIRE_FALSE(reader.ok());
  CHECK(reader.error()->code == ErrorCode::kMalformedPayload);
  CHECK_THAT(reader.error()->text, Catch::Contains("test payload") && Catch::Contains("at byte 2"));
  // Later reads neither advance nor overwrite the first error.
  CHECK(reader.integer<std::uint8_t>() == 0);
  CHECK(reader.offset() == 2);
  reader.fail(ErrorCode::kInternal, "second");
  CHECK(reader.error()->code == ErrorCode::kMalformedPayload);
}

TEST_CASE("every error code has a stable name") {
  CHECK(errorCodeName(ErrorCode::kBadMagic) == "BAD_MAGIC");
  CHECK(errorCodeName(ErrorCode::kFrameTooLarge) == "FRAME_TOO_LARGE");
  CHECK(errorCodeName(ErrorCode::kUnsupported) == "UNSUPPORTED");
  for (std::uint16_t code = 1; code <= 19; ++code) {
    CHECK(errorCodeName(static_cast<ErrorCode>(code)) != "UNKNOWN_ERROR");
  }
  CHECK(errorCodeName(static_cast<ErrorCode>(0)) == "UNKNOWN_ERROR");
  CHECK(errorCodeName(static_cast<ErrorCode>(20)) == "UNKNOWN_ERROR");
}
