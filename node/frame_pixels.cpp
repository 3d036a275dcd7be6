#include "frame_pixels.h"

#include <zlib.h>

#include <cstring>

#include "error.h"
#include "image_io.h"

namespace pvr::node {

std::vector<std::uint8_t> framePixels(const core::Image& frame, const std::array<double, 4>& background,
                                      proto::PixelFormat format, proto::Compression compression) {
  std::vector<std::uint8_t> raw = core::toSrgbRgba8(frame, background);
  const std::size_t channels = proto::channelCount(format);
  if (channels == 3) {
    for (std::size_t i = 0, n = raw.size() / 4; i < n; ++i) std::memmove(&raw[i * 3], &raw[i * 4], 3);
    raw.resize(raw.size() / 4 * 3);
  }
  switch (compression) {
    case proto::Compression::kNone: return raw;
    case proto::Compression::kRle: {
      std::vector<std::uint8_t> out;
      for (std::size_t i = 0; i < raw.size();) {
        std::size_t run = 1;
        while (run < 256 && i + run * channels < raw.size() &&
               std::memcmp(&raw[i], &raw[i + run * channels], channels) == 0)
          ++run;
        out.push_back(std::uint8_t(run - 1));
        out.insert(out.end(), raw.begin() + std::ptrdiff_t(i), raw.begin() + std::ptrdiff_t(i + channels));
        i += run * channels;
      }
      return out;
    }
    case proto::Compression::kZlib: {
      uLongf size = compressBound(uLong(raw.size()));
      std::vector<std::uint8_t> out(size);
      if (compress2(out.data(), &size, raw.data(), uLong(raw.size()), Z_BEST_SPEED) != Z_OK)
        throw Error(ErrorCode::kInternal, "zlib compression failed");
      out.resize(size);
      return out;
    }
  }
  throw Error(ErrorCode::kInternal, "unknown compression");
}

std::vector<std::uint8_t> decompressPixels(const std::vector<std::uint8_t>& bytes, std::size_t expected,
                                           proto::PixelFormat format, proto::Compression compression) {
  const std::size_t channels = proto::channelCount(format);
  std::vector<std::uint8_t> out;
  if (compression == proto::Compression::kNone) {
    out = bytes;
  } else if (compression == proto::Compression::kZlib) {
    out.resize(expected);
    uLongf size = uLongf(expected);
    if (uncompress(out.data(), &size, bytes.data(), uLong(bytes.size())) != Z_OK)
      throw Error(ErrorCode::kBadFile, "zlib: bad pixel stream");
    out.resize(size);
  } else {
    for (std::size_t i = 0; i + channels < bytes.size() + 1 && out.size() < expected; i += 1 + channels) {
      if (i + 1 + channels > bytes.size()) throw Error(ErrorCode::kBadFile, "rle: truncated run");
      for (int k = 0; k <= bytes[i]; ++k) out.insert(out.end(), bytes.begin() + std::ptrdiff_t(i + 1), bytes.begin() + std::ptrdiff_t(i + 1 + channels));
    }
  }
  if (out.size() != expected) throw Error(ErrorCode::kBadFile, "pixels: " + std::to_string(out.size()) + " bytes, expected " + std::to_string(expected));
  return out;
}

}  // namespace pvr::node
