#include "pixel_codec.h"

#include <zlib.h>

#include <cstring>
#include <stdexcept>
#include <string>

namespace pvr::proto {
namespace {

// Deflate's largest expansion: 258 bytes from a 2-bit code at best, so 1032
// output bytes per input byte; the zlib header and trailer add a few bytes.
constexpr std::uint64_t kZlibMaxRatio = 1032;
constexpr std::uint64_t kZlibOverhead = 64;

std::vector<std::uint8_t> rleEncode(std::span<const std::uint8_t> raw, std::size_t channels) {
  std::vector<std::uint8_t> out;
  for (std::size_t i = 0; i < raw.size();) {
    // Extend the run while the next pixel equals this one, up to 256.
    std::size_t run = 1;
    while (run < 256 && i + run * channels < raw.size() &&
           std::memcmp(&raw[i], &raw[i + run * channels], channels) == 0)
      ++run;
    out.push_back(static_cast<std::uint8_t>(run - 1));
    out.insert(out.end(), raw.begin() + static_cast<std::ptrdiff_t>(i),
               raw.begin() + static_cast<std::ptrdiff_t>(i + channels));
    i += run * channels;
  }
  return out;
}

std::vector<std::uint8_t> zlibEncode(std::span<const std::uint8_t> raw) {
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::vector<std::uint8_t> out(size);
  // Level 1: the collector compresses every frame on the critical path.
  const int rc = compress2(out.data(), &size, raw.data(), static_cast<uLong>(raw.size()), Z_BEST_SPEED);
  if (rc != Z_OK) throw std::runtime_error("pvr protocol: zlib compression failed with code " + std::to_string(rc));
  out.resize(size);
  return out;
}

// Error texts name the image: "ImageFrame 64 x 48 RGB8 pixels (RLE): ...".
std::string imageName(const ImageFrame& frame) {
  return "ImageFrame " + std::to_string(frame.width) + " x " + std::to_string(frame.height) +
         (frame.format == PixelFormat::kRgba8 ? " RGBA8" : " RGB8") + " pixels (" +
         std::string(compressionName(frame.compression)) + "): ";
}

ProtocolError malformed(const ImageFrame& frame, const std::string& what) {
  return ProtocolError{ErrorCode::kMalformedPayload, imageName(frame) + what};
}

std::variant<std::vector<std::uint8_t>, ProtocolError> rleDecode(const ImageFrame& frame, std::size_t channels,
                                                                 std::size_t rawBytes) {
  const std::vector<std::uint8_t>& in = frame.pixels;
  const std::size_t runBytes = 1 + channels;
  if (in.size() % runBytes != 0) {
    return malformed(frame, std::to_string(in.size()) + " bytes end inside a run: a run is " +
                                std::to_string(runBytes) + " bytes, the last one has " +
                                std::to_string(in.size() % runBytes));
  }
  // First pass over the count bytes: the runs must cover the image exactly
  // before anything is allocated for it.
  const std::size_t pixelCount = rawBytes / channels;
  std::size_t covered = 0;
  for (std::size_t at = 0; at < in.size(); at += runBytes) {
    const std::size_t run = std::size_t{in[at]} + 1;
    if (run > pixelCount - covered) {
      return malformed(frame, "the run of " + std::to_string(run) + " pixels at byte " + std::to_string(at) +
                                  " runs past the end of the image, which has " +
                                  std::to_string(pixelCount - covered) + " pixels left");
    }
    covered += run;
  }
  if (covered != pixelCount) {
    return malformed(frame, "the runs cover " + std::to_string(covered) + " of the image's " +
                                std::to_string(pixelCount) + " pixels");
  }
  std::vector<std::uint8_t> raw(rawBytes);
  std::uint8_t* out = raw.data();
  for (std::size_t at = 0; at < in.size(); at += runBytes) {
    for (std::size_t k = 0; k <= in[at]; ++k, out += channels) std::memcpy(out, &in[at + 1], channels);
  }
  return raw;
}

std::variant<std::vector<std::uint8_t>, ProtocolError> zlibDecode(const ImageFrame& frame, std::size_t rawBytes) {
  // Deflate expands at most kZlibMaxRatio-fold (zlib's documented bound), so
  // a stream too short for the image is refused before the image is allocated.
  const std::uint64_t mostInflated = std::uint64_t{frame.pixels.size()} * kZlibMaxRatio + kZlibOverhead;
  if (rawBytes > mostInflated) {
    return malformed(frame, "a zlib stream of " + std::to_string(frame.pixels.size()) +
                                " bytes cannot inflate to the image's " + std::to_string(rawBytes) + " bytes");
  }
  // Inflate into exactly rawBytes and stop there, whatever the stream says.
  std::vector<std::uint8_t> raw(rawBytes);
  z_stream z{};
  if (inflateInit(&z) != Z_OK) return ProtocolError{ErrorCode::kInternal, imageName(frame) + "zlib cannot start"};
  z.next_in = const_cast<Bytef*>(frame.pixels.data());
  z.avail_in = static_cast<uInt>(frame.pixels.size());
  z.next_out = raw.data();
  z.avail_out = static_cast<uInt>(rawBytes);
  const int rc = inflate(&z, Z_FINISH);
  const std::size_t produced = rawBytes - z.avail_out;
  const std::size_t unread = z.avail_in;
  const std::string zlibSays = z.msg ? z.msg : "code " + std::to_string(rc);
  inflateEnd(&z);
  const std::string of = std::to_string(rawBytes);
  if (rc == Z_STREAM_END) {
    if (produced != rawBytes)
      return malformed(frame, "the zlib stream inflates to " + std::to_string(produced) + " of " + of + " bytes");
    if (unread != 0)
      return malformed(frame, std::to_string(unread) + " bytes follow the end of the zlib stream");
    return raw;
  }
  if (rc == Z_BUF_ERROR && produced == rawBytes)
    return malformed(frame, "the zlib stream inflates to more than the image's " + of + " bytes");
  if (rc == Z_BUF_ERROR)
    return malformed(frame, "the zlib stream ends after " + std::to_string(produced) + " of " + of + " bytes");
  return malformed(frame, "the zlib stream is damaged (" + zlibSays + ")");
}

}  // namespace

std::vector<std::uint8_t> compressPixels(std::span<const std::uint8_t> raw, PixelFormat format,
                                         Compression compression) {
  const std::size_t channels = channelCount(format);
  if (raw.size() % channels != 0) {
    throw std::invalid_argument("pvr protocol: " + std::to_string(raw.size()) + " pixel bytes are not whole " +
                                std::to_string(channels) + "-channel pixels");
  }
  switch (compression) {
    case Compression::kNone: return std::vector<std::uint8_t>(raw.begin(), raw.end());
    case Compression::kRle: return rleEncode(raw, channels);
    case Compression::kZlib: return zlibEncode(raw);
  }
  throw std::invalid_argument("pvr protocol: compression value " +
                              std::to_string(static_cast<unsigned>(compression)) + " is unknown");
}

void setPixels(ImageFrame& frame, std::span<const std::uint8_t> raw, Compression wanted) {
  const std::uint64_t rawBytes = std::uint64_t{frame.width} * frame.height * channelCount(frame.format);
  if (raw.size() != rawBytes) {
    throw std::invalid_argument("pvr protocol: a " + std::to_string(frame.width) + " x " +
                                std::to_string(frame.height) + " image needs " + std::to_string(rawBytes) +
                                " pixel bytes, got " + std::to_string(raw.size()));
  }
  if (wanted != Compression::kNone) {
    auto packed = compressPixels(raw, frame.format, wanted);
    if (packed.size() < raw.size()) {
      frame.compression = wanted;
      frame.pixels = std::move(packed);
      return;
    }
  }
  frame.compression = Compression::kNone;
  frame.pixels.assign(raw.begin(), raw.end());
}

std::variant<std::vector<std::uint8_t>, ProtocolError> decompressPixels(const ImageFrame& frame, const Limits& limits) {
  // The frame's own rules first: they bound width * height * channels.
  if (auto problem = frame.check(limits)) return std::move(*problem);
  const std::size_t channels = channelCount(frame.format);
  const std::size_t rawBytes = std::size_t{frame.width} * frame.height * channels;
  switch (frame.compression) {
    case Compression::kNone: return frame.pixels;
    case Compression::kRle: return rleDecode(frame, channels, rawBytes);
    case Compression::kZlib: return zlibDecode(frame, rawBytes);
  }
  return malformed(frame, "compression value " + std::to_string(static_cast<unsigned>(frame.compression)) +
                              " is unknown");
}

}  // namespace pvr::proto
