#include "image_codec.h"

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <string>

#include "error.h"

namespace pvr::core {

namespace {

constexpr char kMagic[4] = {'P', 'V', 'R', 'I'};
constexpr std::uint8_t kVersion = 1;
constexpr std::size_t kPixelBytes = 16;
// Bytes of a row's pair (u32 empty, u32 active).
constexpr std::size_t kPairBytes = 8;
// deflate cannot shrink data by more than about 1032:1, so a zlib stream
// that claims to inflate to more than this is lying; the bound is checked
// before the inflate buffer is allocated.
constexpr std::uint64_t kMaxDeflateRatio = 1032;
constexpr std::uint64_t kDeflateSlack = 1024;

static_assert(sizeof(Rgba) == kPixelBytes, "Rgba must be four packed floats");

[[noreturn]] void malformed(const std::string& what) {
  throw Error(ErrorCode::kBadFile, "encoded image: " + what);
}

// Appends n 32-bit words (uint32 or float) little-endian.
template <typename Word>
void appendWords(std::vector<std::byte>& out, const Word* words, std::size_t n) {
  static_assert(sizeof(Word) == 4);
  const std::size_t at = out.size();
  out.resize(at + 4 * n);
  if constexpr (std::endian::native == std::endian::little) {
    std::memcpy(out.data() + at, words, 4 * n);
  } else {
    for (std::size_t i = 0; i < n; ++i) {
      const auto bits = std::bit_cast<std::uint32_t>(words[i]);
      for (int k = 0; k < 4; ++k) out[at + 4 * i + k] = std::byte(bits >> (8 * k));
    }
  }
}

void appendU32(std::vector<std::byte>& out, std::uint32_t v) { appendWords(out, &v, 1); }

void appendPixels(std::vector<std::byte>& out, const Rgba* pixels, std::size_t n) {
  appendWords(out, reinterpret_cast<const float*>(pixels), 4 * n);
}

// Reads little-endian words off a span; every read checks the bytes are there.
class Reader {
 public:
  explicit Reader(std::span<const std::byte> bytes) : bytes_(bytes) {}

  std::size_t remaining() const { return bytes_.size() - pos_; }
  void need(std::size_t n, const char* what) const {
    if (n > remaining())
      malformed(std::string(what) + " needs " + std::to_string(n) + " bytes, " +
                std::to_string(remaining()) + " left");
  }
  std::uint8_t u8(const char* what) {
    need(1, what);
    return std::uint8_t(bytes_[pos_++]);
  }
  std::uint32_t u32(const char* what) {
    need(4, what);
    std::uint32_t v = 0;
    for (int k = 0; k < 4; ++k) v |= std::uint32_t(bytes_[pos_ + k]) << (8 * k);
    pos_ += 4;
    return v;
  }
  std::uint64_t u64(const char* what) {
    const std::uint64_t lo = u32(what);
    return lo | (std::uint64_t(u32(what)) << 32);
  }
  // n pixels of float RGBA into out (skipped when out is null).
  void pixels(Rgba* out, std::size_t n, const char* what) {
    need(n * kPixelBytes, what);
    if (out) {
      if constexpr (std::endian::native == std::endian::little) {
        std::memcpy(out, bytes_.data() + pos_, n * kPixelBytes);
      } else {
        float* f = reinterpret_cast<float*>(out);
        for (std::size_t i = 0; i < 4 * n; ++i) {
          std::uint32_t bits = 0;
          for (int k = 0; k < 4; ++k) bits |= std::uint32_t(bytes_[pos_ + 4 * i + k]) << (8 * k);
          f[i] = std::bit_cast<float>(bits);
        }
      }
    }
    pos_ += n * kPixelBytes;
  }
  std::span<const std::byte> rest() const { return bytes_.subspan(pos_); }

 private:
  std::span<const std::byte> bytes_;
  std::size_t pos_ = 0;
};

bool isEmpty(const Rgba& p) {
  return (std::bit_cast<std::uint32_t>(p.r) | std::bit_cast<std::uint32_t>(p.g) |
          std::bit_cast<std::uint32_t>(p.b) | std::bit_cast<std::uint32_t>(p.a)) == 0;
}

// The rectangle's rows as runs (see image_codec.h); returns the payload.
std::vector<std::byte> runPayload(const Image& image, const PixelRect& r) {
  std::vector<std::byte> out;
  out.reserve(std::size_t(r.height()) * 2 * kPairBytes);
  for (int y = r.y0; y < r.y1; ++y) {
    const Rgba* row = &image.at(r.x0, y);
    const int w = r.width();
    for (int x = 0; x < w;) {
      int active = x;
      while (active < w && isEmpty(row[active])) ++active;
      int end = active;
      while (end < w && !isEmpty(row[end])) ++end;
      appendU32(out, std::uint32_t(active - x));
      appendU32(out, std::uint32_t(end - active));
      appendPixels(out, row + active, std::size_t(end - active));
      x = end;
    }
  }
  return out;
}

std::vector<std::byte> deflateRuns(const std::vector<std::byte>& payload) {
  uLongf size = compressBound(uLong(payload.size()));
  std::vector<std::byte> out(size);
  const int rc =
      compress2(reinterpret_cast<Bytef*>(out.data()), &size,
                reinterpret_cast<const Bytef*>(payload.data()), uLong(payload.size()), 1);
  if (rc != Z_OK)
    throw Error(ErrorCode::kInternal,
                "image codec: zlib compress2 failed (" + std::to_string(rc) + ")");
  out.resize(size);
  return out;
}

// Walks the runs of a kRle payload over a w x h rectangle, checking every
// pair against the row and the bytes left; writes the pixels into `pixels`
// (w * h, already transparent) unless it is null. A first pass with null
// validates everything before the image is allocated.
void walkRuns(std::span<const std::byte> payload, int w, int h, Rgba* pixels) {
  Reader in(payload);
  for (int y = 0; y < h; ++y) {
    Rgba* row = pixels ? pixels + std::size_t(y) * std::size_t(w) : nullptr;
    std::uint64_t x = 0;
    while (x < std::uint64_t(w)) {
      const std::uint64_t empty = in.u32("run pair");
      const std::uint64_t active = in.u32("run pair");
      if (empty + active == 0)
        malformed("row " + std::to_string(y) + ": a run pair covers no pixel");
      if (empty + active > std::uint64_t(w) - x)
        malformed("row " + std::to_string(y) + ": runs of " + std::to_string(empty) + " and " +
                  std::to_string(active) + " pixels at x = " + std::to_string(x) +
                  " overrun the row of " + std::to_string(w));
      in.pixels(row ? row + x + empty : nullptr, std::size_t(active), "active pixels");
      x += empty + active;
    }
  }
  if (in.remaining() != 0)
    malformed(std::to_string(in.remaining()) + " bytes after the last row of runs");
}

std::vector<std::byte> inflateRuns(std::span<const std::byte> stream, std::uint64_t size,
                                   std::uint64_t bound) {
  if (size > bound)
    malformed("zlib payload claims " + std::to_string(size) + " bytes, at most " +
              std::to_string(bound) + " fit the rectangle");
  if (size > std::uint64_t(stream.size()) * kMaxDeflateRatio + kDeflateSlack)
    malformed("zlib payload claims " + std::to_string(size) + " bytes from a " +
              std::to_string(stream.size()) + "-byte stream");
  std::vector<std::byte> out(static_cast<std::size_t>(size));
  uLongf produced = uLongf(size);
  uLong consumed = uLong(stream.size());
  // A zero-length destination makes zlib use a scratch byte; that is fine.
  const int rc = uncompress2(reinterpret_cast<Bytef*>(out.data()), &produced,
                             reinterpret_cast<const Bytef*>(stream.data()), &consumed);
  if (rc != Z_OK)
    malformed("zlib stream does not inflate to the stated size (zlib error " + std::to_string(rc) +
              ")");
  if (produced != size) malformed("zlib stream inflates to fewer bytes than stated");
  if (consumed != stream.size()) malformed("bytes after the zlib stream");
  return out;
}

}  // namespace

EncodedImage encodeImage(const Image& image, const PixelRect& rect, ImageCodec codec) {
  const PixelRect r = rect.intersect(image.rect());
  if (image.frameWidth() > kImageCodecMaxSide || image.frameHeight() > kImageCodecMaxSide ||
      std::uint64_t(r.width()) * std::uint64_t(r.height()) > kImageCodecMaxPixels)
    throw Error(ErrorCode::kInvalidArgument,
                "image codec: a " + std::to_string(image.frameWidth()) + "x" +
                    std::to_string(image.frameHeight()) +
                    " frame or its rectangle exceeds the codec's limits");
  const std::size_t rawBytes = std::size_t(r.width()) * std::size_t(r.height()) * kPixelBytes;

  // Payload in the codec asked for; kAuto keeps the smaller sparse form
  // (plain runs on a tie: cheaper to decode).
  std::vector<std::byte> payload;
  std::uint64_t payloadSize = 0;
  ImageCodec written = codec;
  switch (codec) {
    case ImageCodec::kRaw:
      for (int y = r.y0; y < r.y1; ++y)
        appendPixels(payload, &image.at(r.x0, y), std::size_t(r.width()));
      payloadSize = payload.size();
      break;
    case ImageCodec::kRle:
      payload = runPayload(image, r);
      payloadSize = payload.size();
      break;
    case ImageCodec::kRleZlib:
    case ImageCodec::kAuto: {
      std::vector<std::byte> runs = runPayload(image, r);
      payloadSize = runs.size();
      payload = deflateRuns(runs);
      written = ImageCodec::kRleZlib;
      if (codec == ImageCodec::kAuto && runs.size() <= payload.size()) {
        payload = std::move(runs);
        written = ImageCodec::kRle;
      }
      break;
    }
    default:
      throw Error(ErrorCode::kInvalidArgument,
                  "image codec: unknown codec " + std::to_string(int(codec)));
  }

  EncodedImage encoded;
  encoded.rawBytes = rawBytes;
  std::vector<std::byte>& out = encoded.bytes;
  out.reserve(kImageCodecHeaderBytes + payload.size());
  for (char c : kMagic) out.push_back(std::byte(c));
  out.push_back(std::byte(kVersion));
  out.push_back(std::byte(written));
  out.push_back(std::byte(0));
  out.push_back(std::byte(0));
  const std::uint32_t fields[8] = {std::uint32_t(image.frameWidth()),
                                   std::uint32_t(image.frameHeight()),
                                   std::uint32_t(r.x0),
                                   std::uint32_t(r.y0),
                                   std::uint32_t(r.x1),
                                   std::uint32_t(r.y1),
                                   std::uint32_t(payloadSize),
                                   std::uint32_t(payloadSize >> 32)};
  appendWords(out, fields, 8);
  out.insert(out.end(), payload.begin(), payload.end());
  return encoded;
}

EncodedImage encodeImage(const Image& image, ImageCodec codec) {
  return encodeImage(image, image.rect(), codec);
}

Image decodeImage(std::span<const std::byte> bytes) {
  // Header: magic, version, codec, frame, rectangle, payload size.
  Reader in(bytes);
  in.need(kImageCodecHeaderBytes, "header");
  for (char c : kMagic)
    if (in.u8("magic") != std::uint8_t(c)) malformed("bad magic (not a PVR image)");
  if (const std::uint8_t v = in.u8("version"); v != kVersion)
    malformed("version " + std::to_string(v) + ", this build reads " + std::to_string(kVersion));
  const std::uint8_t codecByte = in.u8("codec");
  if (codecByte > std::uint8_t(ImageCodec::kRleZlib))
    malformed("unknown codec " + std::to_string(codecByte));
  const auto codec = ImageCodec(codecByte);
  if (in.u8("reserved") != 0 || in.u8("reserved") != 0)
    malformed("reserved header bytes are not zero");
  const std::uint32_t frameWidth = in.u32("frame"), frameHeight = in.u32("frame");
  if (frameWidth > std::uint32_t(kImageCodecMaxSide) ||
      frameHeight > std::uint32_t(kImageCodecMaxSide))
    malformed("frame " + std::to_string(frameWidth) + "x" + std::to_string(frameHeight) +
              " exceeds " + std::to_string(kImageCodecMaxSide) + " a side");
  std::int64_t edge[4];
  for (std::int64_t& e : edge) e = std::int32_t(in.u32("rectangle"));
  const std::int64_t x0 = edge[0], y0 = edge[1], x1 = edge[2], y1 = edge[3];
  if (x0 < 0 || y0 < 0 || x0 > x1 || y0 > y1 || x1 > frameWidth || y1 > frameHeight)
    malformed("rectangle [" + std::to_string(x0) + ", " + std::to_string(x1) + ") x [" +
              std::to_string(y0) + ", " + std::to_string(y1) + ") is not inside the " +
              std::to_string(frameWidth) + "x" + std::to_string(frameHeight) + " frame");
  const PixelRect rect{int(x0), int(y0), int(x1), int(y1)};
  const int w = rect.width(), h = rect.height();
  const std::uint64_t pixelCount = std::uint64_t(w) * std::uint64_t(h);
  if (pixelCount > kImageCodecMaxPixels) malformed("rectangle exceeds the pixel limit");
  const std::uint64_t payloadSize = in.u64("payload size");

  // Payload: checked whole before the image is allocated.
  std::span<const std::byte> payload = in.rest();
  std::vector<std::byte> inflated;
  const std::uint64_t rawSize = pixelCount * kPixelBytes;
  if (codec == ImageCodec::kRaw) {
    if (payloadSize != rawSize || payload.size() != rawSize)
      malformed("raw payload of " + std::to_string(payload.size()) + " bytes (header: " +
                std::to_string(payloadSize) + "), the rectangle needs " + std::to_string(rawSize));
  } else if (codec == ImageCodec::kRle) {
    if (payloadSize != payload.size())
      malformed("run payload of " + std::to_string(payload.size()) + " bytes, header says " +
                std::to_string(payloadSize));
    walkRuns(payload, w, h, nullptr);
  } else {
    // Every pair covers at least one pixel: a row costs at most 24 bytes a pixel.
    inflated = inflateRuns(payload, payloadSize, pixelCount * (kPairBytes + kPixelBytes));
    payload = inflated;
    walkRuns(payload, w, h, nullptr);
  }

  Image image(int(frameWidth), int(frameHeight), rect);
  if (codec == ImageCodec::kRaw)
    Reader(payload).pixels(image.pixels().data(), std::size_t(pixelCount), "raw pixels");
  else
    walkRuns(payload, w, h, image.pixels().data());
  return image;
}

}  // namespace pvr::core
