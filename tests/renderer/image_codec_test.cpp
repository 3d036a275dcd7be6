// Sparse image codecs: lossless, small where images are sparse, and
// hostile bytes throw pvr::Error instead of crashing or allocating.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "error.h"
#include "image_codec.h"

namespace pvr::core {
namespace {

constexpr ImageCodec kCodecs[] = {ImageCodec::kRaw, ImageCodec::kRle, ImageCodec::kRleZlib,
                                  ImageCodec::kAuto};

// Same frame, same rectangle, same bits in every pixel.
bool bitIdentical(const Image& a, const Image& b) {
  return a.frameWidth() == b.frameWidth() && a.frameHeight() == b.frameHeight() &&
         a.rect() == b.rect() && a.pixels().size() == b.pixels().size() &&
         (a.pixels().empty() ||
          std::memcmp(a.pixels().data(), b.pixels().data(), a.pixels().size() * sizeof(Rgba)) == 0);
}

Image randomImage(int w, int h, const PixelRect& rect, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  Image image(w, h, rect);
  for (Rgba& p : image.pixels()) p = {u(rng), u(rng), u(rng), u(rng)};
  return image;
}

// Mostly transparent: two discs of colour, and pixels whose bits are odd
// but not empty (negative zero, alpha 0 with colour, NaN, a denormal).
Image sparseImage(int w, int h) {
  Image image = Image::fullFrame(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double d1 = std::hypot(x - 0.3 * w, y - 0.4 * h),
                   d2 = std::hypot(x - 0.75 * w, y - 0.7 * h);
      if (d1 < 0.12 * w) image.at(x, y) = {0.5f, 0.25f, float(x) / w, 0.75f};
      if (d2 < 0.05 * w) image.at(x, y) = {0.1f, 0.2f, 0.3f, float(y) / h};
    }
  image.at(0, 0) = {-0.0f, 0, 0, 0};
  image.at(w - 1, 0) = {0.2f, 0, 0, 0};
  image.at(w / 2, h - 1) = {0, 0, 0, std::numeric_limits<float>::quiet_NaN()};
  image.at(w - 1, h - 1) = {0, std::numeric_limits<float>::denorm_min(), 0, 0};
  return image;
}

std::vector<std::byte> encode(const Image& image, ImageCodec codec) {
  return encodeImage(image, codec).bytes;
}

void putU32(std::vector<std::byte>& bytes, std::size_t at, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) bytes[at + std::size_t(k)] = std::byte(v >> (8 * k));
}
void putU64(std::vector<std::byte>& bytes, std::size_t at, std::uint64_t v) {
  putU32(bytes, at, std::uint32_t(v));
  putU32(bytes, at + 4, std::uint32_t(v >> 32));
}

// Offsets of the layout in image_codec.h.
constexpr std::size_t kFrameAt = 8, kRectAt = 16, kPayloadSizeAt = 32;
constexpr std::size_t kPayloadAt = kImageCodecHeaderBytes;

}  // namespace

TEST_CASE("codec round trip is bit-exact for every codec", "[codec]") {
  std::vector<Image> images;
  images.push_back(Image());                                 // no frame at all
  images.push_back(Image::fullFrame(32, 16));                // all transparent
  images.push_back(randomImage(37, 23, {0, 0, 37, 23}, 1));  // all active
  images.push_back(sparseImage(64, 48));
  images.push_back(randomImage(64, 48, {5, 3, 40, 30}, 2));  // a rectangle of the frame
  images.push_back(Image(64, 48, {10, 10, 10, 20}));         // an empty rectangle
  images.push_back(randomImage(1, 1, {0, 0, 1, 1}, 3));
  for (const Image& image : images)
    for (ImageCodec codec : kCodecs) {
      INFO("frame " << image.frameWidth() << "x" << image.frameHeight() << " codec " << int(codec));
      const EncodedImage e = encodeImage(image, codec);
      CHECK(e.rawBytes == image.pixels().size() * sizeof(Rgba));
      CHECK(bitIdentical(decodeImage(e.bytes), image));
    }
}

TEST_CASE("codec encodes a sub-rectangle, clipped to the image's rectangle", "[codec]") {
  const Image image = randomImage(64, 48, {5, 3, 40, 30}, 4);
  const PixelRect asked[] = {{10, 10, 20, 25}, {0, 0, 64, 48}, {30, 20, 64, 48}, {50, 40, 60, 45}};
  for (const PixelRect& r : asked)
    for (ImageCodec codec : kCodecs) {
      const PixelRect kept = r.intersect(image.rect());
      const Image decoded = decodeImage(encodeImage(image, r, codec).bytes);
      CHECK(decoded.frameWidth() == 64);
      CHECK(decoded.frameHeight() == 48);
      CHECK(decoded.rect() == kept);
      bool same = true;
      for (int y = kept.y0; y < kept.y1; ++y)
        for (int x = kept.x0; x < kept.x1; ++x)
          same &= std::memcmp(&decoded.at(x, y), &image.at(x, y), sizeof(Rgba)) == 0;
      CHECK(same);
    }
}

TEST_CASE("codec sizes: runs beat raw on sparse images, auto takes the smaller", "[codec]") {
  const Image sparse = sparseImage(128, 96);
  const std::size_t raw = encode(sparse, ImageCodec::kRaw).size();
  const std::size_t rle = encode(sparse, ImageCodec::kRle).size();
  CHECK(rle < raw / 3);
  const Image images[] = {sparse, Image::fullFrame(64, 64), randomImage(64, 64, {0, 0, 64, 64}, 5)};
  for (const Image& image : images) {
    const std::size_t runs = encode(image, ImageCodec::kRle).size();
    const std::size_t zipped = encode(image, ImageCodec::kRleZlib).size();
    const std::size_t best = encode(image, ImageCodec::kAuto).size();
    CHECK(best <= runs);
    CHECK(best <= zipped);
    CHECK(best == std::min(runs, zipped));
  }
  // An all-transparent frame costs a pair a row.
  CHECK(encode(Image::fullFrame(64, 64), ImageCodec::kRle).size() ==
        kImageCodecHeaderBytes + 64 * 8);
}

TEST_CASE("codec decode rejects malformed bytes with pvr::Error", "[codec]") {
  const Image image = sparseImage(24, 16);
  const std::vector<std::byte> rle = encode(image, ImageCodec::kRle);
  const std::vector<std::byte> zlib = encode(image, ImageCodec::kRleZlib);
  const std::vector<std::byte> raw = encode(image, ImageCodec::kRaw);
  REQUIRE(bitIdentical(decodeImage(rle), image));

  SECTION("every truncation") {
    for (const std::vector<std::byte>* full : {&rle, &zlib, &raw})
      for (std::size_t n = 0; n < full->size(); ++n) {
        INFO("first " << n << " of " << full->size() << " bytes");
        CHECK_THROWS_AS(decodeImage(std::span(full->data(), n)), Error);
      }
  }
  SECTION("trailing bytes") {
    for (std::vector<std::byte> bytes : {rle, zlib, raw}) {
      bytes.push_back(std::byte(0));
      CHECK_THROWS_AS(decodeImage(bytes), Error);
    }
  }
  SECTION("header fields") {
    auto mutated = [&](auto change) {
      std::vector<std::byte> bytes = rle;
      change(bytes);
      return bytes;
    };
    CHECK_THROWS_AS(decodeImage(mutated([](auto& b) { b[0] = std::byte('X'); })), Error);
    CHECK_THROWS_AS(decodeImage(mutated([](auto& b) { b[4] = std::byte(2); })), Error);  // version
    CHECK_THROWS_AS(decodeImage(mutated([](auto& b) { b[5] = std::byte(3); })), Error);  // codec
    CHECK_THROWS_AS(decodeImage(mutated([](auto& b) { b[5] = std::byte(255); })), Error);  // kAuto
    CHECK_THROWS_AS(decodeImage(mutated([](auto& b) { b[6] = std::byte(1); })), Error);  // reserved
    // Rectangle outside the frame, inverted, negative; frame beyond the limit.
    CHECK_THROWS_AS(decodeImage(mutated([](auto& b) { putU32(b, kRectAt + 8, 25); })), Error);
    CHECK_THROWS_AS(decodeImage(mutated([](auto& b) { putU32(b, kRectAt + 12, 17); })), Error);
    CHECK_THROWS_AS(decodeImage(mutated([](auto& b) { putU32(b, kRectAt, 30); })), Error);
    CHECK_THROWS_AS(decodeImage(mutated([](auto& b) { putU32(b, kRectAt + 4, 0xFFFFFFFFu); })),
                    Error);
    CHECK_THROWS_AS(decodeImage(mutated([](auto& b) { putU32(b, kFrameAt, 10); })), Error);
    CHECK_THROWS_AS(decodeImage(mutated([](auto& b) { putU32(b, kFrameAt, 1u << 20); })), Error);
    // Payload size disagreeing with the bytes.
    CHECK_THROWS_AS(decodeImage(mutated([](auto& b) { putU64(b, kPayloadSizeAt, b.size()); })),
                    Error);
    CHECK_THROWS_AS(decodeImage(mutated([](auto& b) { putU64(b, kPayloadSizeAt, ~0ull); })), Error);
  }
  SECTION("run lengths") {
    auto withFirstPair = [&](std::uint32_t empty, std::uint32_t active) {
      std::vector<std::byte> bytes = rle;
      putU32(bytes, kPayloadAt, empty);
      putU32(bytes, kPayloadAt + 4, active);
      return bytes;
    };
    CHECK_THROWS_AS(decodeImage(withFirstPair(0xFFFFFFFFu, 0)), Error);
    CHECK_THROWS_AS(decodeImage(withFirstPair(0, 0xFFFFFFFFu)), Error);
    CHECK_THROWS_AS(decodeImage(withFirstPair(25, 0)), Error);  // past the row
    CHECK_THROWS_AS(decodeImage(withFirstPair(0, 0)), Error);   // covers nothing
    CHECK_THROWS_AS(decodeImage(withFirstPair(0x80000000u, 0x80000000u)),
                    Error);  // wraps in 32 bits
  }
  SECTION("zlib payloads") {
    // A stream claiming to inflate to far more than it could, or to more
    // than the rectangle can use: refused before allocating.
    std::vector<std::byte> bytes = zlib;
    putU64(bytes, kPayloadSizeAt, 1ull << 40);
    CHECK_THROWS_AS(decodeImage(bytes), Error);
    bytes = zlib;
    putU64(bytes, kPayloadSizeAt, 24 * 24 * 16 + 1);
    CHECK_THROWS_AS(decodeImage(bytes), Error);
    // Inflates to fewer bytes than stated; garbage instead of a stream.
    bytes = zlib;
    putU64(bytes, kPayloadSizeAt, 100);
    CHECK_THROWS_AS(decodeImage(bytes), Error);
    bytes = zlib;
    for (std::size_t i = kPayloadAt; i < bytes.size(); ++i) bytes[i] = std::byte(0x5A);
    CHECK_THROWS_AS(decodeImage(bytes), Error);
  }
  SECTION("a huge sparse rectangle is bounded by the pixel limit") {
    // 16384 x 16384 empty rows cost 8 bytes a row, but 2^28 pixels exceed
    // the limit: refused without allocating 4 GiB.
    std::vector<std::byte> bytes(kImageCodecHeaderBytes);
    const char magic[4] = {'P', 'V', 'R', 'I'};
    for (int i = 0; i < 4; ++i) bytes[std::size_t(i)] = std::byte(magic[i]);
    bytes[4] = std::byte(1);
    bytes[5] = std::byte(ImageCodec::kRle);
    putU32(bytes, kFrameAt, 16384);
    putU32(bytes, kFrameAt + 4, 16384);
    putU32(bytes, kRectAt + 8, 16384);
    putU32(bytes, kRectAt + 12, 16384);
    putU64(bytes, kPayloadSizeAt, 16384 * 8);
    for (int row = 0; row < 16384; ++row) {
      const std::size_t at = bytes.size();
      bytes.resize(at + 8);
      putU32(bytes, at, 16384);
      putU32(bytes, at + 4, 0);
    }
    CHECK_THROWS_AS(decodeImage(bytes), Error);
  }
}

// Random corruption: every result is an image or a pvr::Error, nothing else.
TEST_CASE("codec decode survives random corruption", "[codec]") {
  const Image image = sparseImage(20, 12);
  std::mt19937 rng(7);
  for (ImageCodec codec : {ImageCodec::kRle, ImageCodec::kRleZlib, ImageCodec::kRaw}) {
    const std::vector<std::byte> good = encode(image, codec);
    std::uniform_int_distribution<std::size_t> where(0, good.size() - 1);
    std::uniform_int_distribution<int> value(0, 255);
    int decoded = 0, refused = 0;
    for (int trial = 0; trial < 2000; ++trial) {
      std::vector<std::byte> bytes = good;
      for (int k = 0; k < 1 + trial % 4; ++k) bytes[where(rng)] = std::byte(value(rng));
      try {
        const Image out = decodeImage(bytes);
        CHECK(out.pixels().size() ==
              std::size_t(out.rect().width()) * std::size_t(out.rect().height()));
        ++decoded;
      } catch (const Error&) {
        ++refused;
      }
    }
    INFO("codec " << int(codec) << ": " << decoded << " decoded, " << refused << " refused");
    CHECK(decoded + refused == 2000);
    CHECK(refused > 0);
  }
}

TEST_CASE("codec encode refuses frames beyond its limits", "[codec]") {
  const Image wide(kImageCodecMaxSide + 1, 1, {0, 0, 1, 1});
  CHECK_THROWS_AS(encodeImage(wide, ImageCodec::kRle), Error);
}

}  // namespace pvr::core
