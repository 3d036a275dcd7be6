#include "image_limits.h"

#include <string>

namespace pvr::proto {

std::uint64_t imageFramePayloadBytes(std::uint64_t width, std::uint64_t height, PixelFormat format) {
  // frame number, width, height (u32 each), format, compression (u8 each),
  // the timing record, u32 pixel byte count, then the pixels.
  constexpr std::uint64_t kFixed = 3 * 4 + 2 * 1 + kFrameTimingBytes + 4;
  return kFixed + width * height * channelCount(format);
}

std::optional<ProtocolError> checkImageSize(std::uint64_t width, std::uint64_t height, PixelFormat format,
                                            const Limits& limits) {
  const std::string size = std::to_string(width) + " x " + std::to_string(height);
  if (width == 0 || height == 0) return ProtocolError{ErrorCode::kBadArgument, "image of " + size + " pixels is empty"};
  // Refuse sides past 2^32 first, so the products below cannot overflow.
  if (width > 0xffffffffull || height > 0xffffffffull || width * height > limits.maxImagePixels)
    return ProtocolError{ErrorCode::kLimitExceeded, "image of " + size + " pixels exceeds the protocol's limit of " +
                                                        std::to_string(limits.maxImagePixels) + " pixels"};
  const std::uint64_t bytes = imageFramePayloadBytes(width, height, format);
  if (bytes > limits.maxFrameBytes)
    return ProtocolError{ErrorCode::kLimitExceeded,
                         "image of " + size + " pixels in " + std::to_string(channelCount(format)) +
                             " channels needs frames of " + std::to_string(bytes) +
                             " bytes, over the protocol's limit of " + std::to_string(limits.maxFrameBytes) +
                             " bytes per frame"};
  return std::nullopt;
}

}  // namespace pvr::proto
