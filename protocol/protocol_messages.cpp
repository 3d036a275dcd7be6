#include "protocol_messages.h"

namespace pvr::proto {

std::optional<ProtocolError> ImageFrame::check(const Limits& limits) const {
  if (width == 0 || height == 0) {
    return ProtocolError{ErrorCode::kMalformedPayload,
                         "image of " + std::to_string(width) + " x " + std::to_string(height) + " pixels is empty"};
  }
  // Both factors < 2^32, so the product fits 64 bits.
  const std::uint64_t pixelCount = std::uint64_t{width} * height;
  if (pixelCount > limits.maxImagePixels) {
    return ProtocolError{ErrorCode::kLimitExceeded, "image of " + std::to_string(width) + " x " +
                                                        std::to_string(height) + " pixels exceeds the limit of " +
                                                        std::to_string(limits.maxImagePixels) + " pixels"};
  }
  const std::uint64_t rawBytes = pixelCount * channelCount(format);
  if (compression == Compression::kNone && pixels.size() != rawBytes) {
    return ProtocolError{ErrorCode::kMalformedPayload,
                         "uncompressed " + std::to_string(width) + " x " + std::to_string(height) + " image needs " +
                             std::to_string(rawBytes) + " pixel bytes, got " + std::to_string(pixels.size())};
  }
  return std::nullopt;
}

}  // namespace pvr::proto
