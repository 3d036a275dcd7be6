// No length read off the wire sizes an allocation before the bytes it
// describes have arrived (or, for pixels, before they are known to cover the
// image). This executable replaces the global operator new
// to record the largest single allocation made while a probe is open.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <new>

#include "raw_frame.h"

using namespace pvr::proto;
using namespace pvr::proto::testing;

namespace {

bool gProbing = false;
std::size_t gLargest = 0;

// Records the largest allocation made by `work`.
template <class F>
std::size_t largestAllocationDuring(F&& work) {
  gLargest = 0;
  gProbing = true;
  work();
  gProbing = false;
  return gLargest;
}

}  // namespace

void* operator new(std::size_t bytes) {
  if (gProbing && bytes > gLargest) gLargest = bytes;
  if (void* p = std::malloc(bytes ? bytes : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

TEST_CASE("the allocation probe sees allocations") {
  const std::size_t largest = largestAllocationDuring([] { std::vector<std::uint8_t> v(123456); });
  CHECK(largest == 123456);
}

TEST_CASE("a header announcing 4 GiB allocates nothing of that size") {
  const auto header = rawFrame({.type = ImageFrame::kWire.type, .payloadBytes = 0xFFFFFFFF}, {});
  FrameDecoder decoder;
  const std::size_t largest = largestAllocationDuring([&] {
    for (std::uint8_t byte : header) decoder.feed(std::span(&byte, 1));
  });
  REQUIRE(decoder.error().has_value());
  CHECK(decoder.error()->code == ErrorCode::kFrameTooLarge);
  CHECK(largest < 1024);
}

TEST_CASE("an allowed 60 MiB frame buffers only the bytes that arrived") {
  const std::uint32_t announced = 60u << 20;
  const auto start = rawFrame({.type = ImageFrame::kWire.type, .payloadBytes = announced},
                              std::vector<std::uint8_t>(4096, 0));
  FrameDecoder decoder;
  const std::size_t largest = largestAllocationDuring([&] {
    for (std::size_t at = 0; at < start.size(); at += 512) {
      decoder.feed(std::span(start).subspan(at, std::min<std::size_t>(512, start.size() - at)));
    }
  });
  CHECK_FALSE(decoder.error().has_value());
  CHECK(decoder.bufferedBytes() == start.size());
  // Geometric growth stays within twice what arrived.
  CHECK(largest <= 2 * start.size());
}

TEST_CASE("lengths inside a payload are checked before anything is sized from them") {
  // A Hello whose string claims 0xFFFFFFF0 bytes, a SessionOpen whose list
  // claims 2^31 clusters, an image whose pixel array claims 2^32-1 bytes.
  const std::vector<std::vector<std::uint8_t>> frames{
      rawFrame({}, payload([](ByteWriter& w) { w.integer<std::uint32_t>(0xFFFFFFF0); })),
      rawFrame({.type = SessionOpen::kWire.type}, payload([](ByteWriter& w) {
                 w.integer<std::uint32_t>(1);
                 w.integer<std::uint32_t>(0x80000000);
               })),
      rawFrame({.type = ImageFrame::kWire.type}, payload([](ByteWriter& w) {
                 for (int i = 0; i < 3; ++i) w.integer<std::uint32_t>(1);
                 w.integer<std::uint16_t>(0);
                 for (int i = 0; i < 5; ++i) w.f64(0);
                 w.integer<std::uint32_t>(0xFFFFFFFF);
               })),
  };
  for (const auto& frame : frames) {
    DecodeResult result;
    const std::size_t largest = largestAllocationDuring([&] { result = decodeFrame(frame); });
    REQUIRE(std::holds_alternative<ProtocolError>(result));
    CHECK(std::get<ProtocolError>(result).code == ErrorCode::kMalformedPayload);
    CHECK(largest < 1024);
  }
}

TEST_CASE("the relay hands out a complete ImageFrame without copying its pixels") {
  // All but the last two bytes arrive, then one more: the buffer has grown
  // to the whole frame. The last byte completes it: the decoder now
  // allocates the pixel array; the relay hands out the bytes it holds and
  // allocates nothing of that size.
  ImageFrame image{0, 512, 512, PixelFormat::kRgba8, Compression::kNone, {}, std::vector<std::uint8_t>(512 * 512 * 4, 9)};
  const auto frame = encode(image, 1, kFlagFinal);
  const auto allButLast = [&](auto& receiver) {
    receiver.feed(std::span(frame).first(frame.size() - 2));
    receiver.feed(std::span(frame).subspan(frame.size() - 2, 1));
  };
  FrameRelay relay;
  allButLast(relay);
  std::optional<RelayItem> item;
  const std::size_t largest = largestAllocationDuring([&] {
    relay.feed(std::span(frame).last(1));
    item = relay.pop();
  });
  REQUIRE(item);
  REQUIRE(std::holds_alternative<RelayedFrame>(*item));
  CHECK(std::get<RelayedFrame>(*item).bytes == frame);
  CHECK(largest < 1024);

  FrameDecoder decoder;
  allButLast(decoder);
  const std::size_t decoderLargest = largestAllocationDuring([&] { decoder.feed(std::span(frame).last(1)); });
  CHECK(decoderLargest >= image.pixels.size());  // the probe would see a copy
}

TEST_CASE("the pixel decoder refuses a tiny stream claiming a large image before allocating the image") {
  // 4096 x 4096 RGB passes the image limits (48 MiB); a few bytes cannot be it.
  ImageFrame rle{0, 4096, 4096, PixelFormat::kRgb8, Compression::kRle, {}, {255, 1, 2, 3, 255, 1, 2, 3}};
  ImageFrame zlib{0, 4096, 4096, PixelFormat::kRgb8, Compression::kZlib, {}, {0x78, 0x01, 1, 2, 3, 4, 5, 6}};
  for (const ImageFrame& frame : {rle, zlib}) {
    std::variant<std::vector<std::uint8_t>, ProtocolError> result;
    const std::size_t largest = largestAllocationDuring([&] { result = decompressPixels(frame); });
    REQUIRE(std::holds_alternative<ProtocolError>(result));
    CHECK(std::get<ProtocolError>(result).code == ErrorCode::kMalformedPayload);
    CHECK(largest < 1024);
  }
}
