#include "protocol_messages.h"

#include <cmath>

#include "image_limits.h"

namespace pvr::proto {

std::optional<ProtocolError> RenderRotation::check(const Limits& limits) const {
  const std::string steps = "steps " + std::to_string(start) + " to " + std::to_string(end);
  if (stepsPerTurn == 0) {
    return ProtocolError{ErrorCode::kBadArgument, "rotation of " + steps + " has 0 steps per turn; it needs at least 1"};
  }
  if (end < start) {
    return ProtocolError{ErrorCode::kBadArgument, "rotation of " + steps + ": the end step is below the start step"};
  }
  // 64-bit: end - start + 1 reaches 2^32 for the widest int32 range.
  const std::int64_t frames = std::int64_t{end} - start + 1;
  if (frames > limits.maxRotationFrames) {
    return ProtocolError{ErrorCode::kLimitExceeded, "rotation of " + steps + " asks for " + std::to_string(frames) +
                                                        " frames, over the protocol's limit of " +
                                                        std::to_string(limits.maxRotationFrames) +
                                                        " frames per request"};
  }
  // The receiver divides the axis by its length: the length must be a
  // finite nonzero number (hypot neither underflows nor overflows early).
  const double length = std::hypot(axis[0], axis[1], axis[2]);
  if (!(length > 0) || !std::isfinite(length)) {
    return ProtocolError{ErrorCode::kBadArgument, "rotation axis (" + std::to_string(axis[0]) + ", " +
                                                      std::to_string(axis[1]) + ", " + std::to_string(axis[2]) +
                                                      ") is not a finite nonzero vector"};
  }
  return std::nullopt;
}

std::optional<ProtocolError> RenderTimeSteps::check(const Limits& limits) const {
  const std::string steps = "time steps " + std::to_string(first) + " to " + std::to_string(last);
  if (stride == 0) return ProtocolError{ErrorCode::kBadArgument, steps + " with stride 0; the stride must be at least 1"};
  if (last < first) return ProtocolError{ErrorCode::kBadArgument, steps + ": the last step is below the first"};
  const std::uint64_t frames = (std::uint64_t{last} - first) / stride + 1;
  if (frames > limits.maxRotationFrames) {
    return ProtocolError{ErrorCode::kLimitExceeded, steps + " ask for " + std::to_string(frames) +
                                                        " frames, over the protocol's limit of " +
                                                        std::to_string(limits.maxRotationFrames) +
                                                        " frames per request"};
  }
  return std::nullopt;
}

std::optional<ProtocolError> RenderSteps::check(const Limits& limits) const {
  const std::string what = "render " + std::to_string(steps) + " steps every " + std::to_string(every);
  if (steps == 0) return ProtocolError{ErrorCode::kBadArgument, what + ": the steps must be at least 1"};
  if (every == 0) return ProtocolError{ErrorCode::kBadArgument, what + ": every must be at least 1"};
  if (frameCount() > limits.maxRotationFrames) {
    return ProtocolError{ErrorCode::kLimitExceeded, what + " asks for " + std::to_string(frameCount()) +
                                                        " frames, over the protocol's limit of " +
                                                        std::to_string(limits.maxRotationFrames) +
                                                        " frames per request"};
  }
  return std::nullopt;
}

std::optional<ProtocolError> RenderInteractive::check(const Limits& limits) const {
  if (reduction < 2 || reduction > kMaxInteractiveReduction)
    return ProtocolError{ErrorCode::kBadArgument, "interactive render with reduction " + std::to_string(reduction) +
                                                      "; it must be 2 to " +
                                                      std::to_string(kMaxInteractiveReduction) + " pixels per axis"};
  return rotation().check(limits);
}

bool isRenderRequest(const Message& m) {
  return std::holds_alternative<RenderFrame>(m) || std::holds_alternative<RenderRotation>(m) ||
         std::holds_alternative<RenderTimeSteps>(m) || std::holds_alternative<RenderSteps>(m) ||
         std::holds_alternative<RenderInteractive>(m);
}

bool isQuery(const Message& m) {
  return std::holds_alternative<StatusRequest>(m) || std::holds_alternative<PerformanceRequest>(m) ||
         std::holds_alternative<CatalogRequest>(m);
}

std::optional<ProtocolError> ImageFrame::checkHead(std::uint64_t pixelBytes, const Limits& limits) const {
  const std::string size = std::to_string(width) + " x " + std::to_string(height);
  if (width == 0 || height == 0) {
    return ProtocolError{ErrorCode::kMalformedPayload, "image of " + size + " pixels is empty"};
  }
  if (auto tooLarge = checkImageSize(width, height, format, limits)) return tooLarge;
  // Both factors < 2^32 and their product passed the pixel limit.
  const std::uint64_t rawBytes = std::uint64_t{width} * height * channelCount(format);
  if (compression == Compression::kNone && pixelBytes != rawBytes) {
    return ProtocolError{ErrorCode::kMalformedPayload, "uncompressed " + size + " image needs " +
                                                           std::to_string(rawBytes) + " pixel bytes, got " +
                                                           std::to_string(pixelBytes)};
  }
  if (compression != Compression::kNone && pixelBytes >= rawBytes) {
    return ProtocolError{ErrorCode::kMalformedPayload,
                         std::string(compressionName(compression)) + " pixels of " + std::to_string(pixelBytes) +
                             " bytes are not fewer than the " + std::to_string(rawBytes) +
                             " bytes of the uncompressed " + size +
                             " image; such a frame must be sent with compression none"};
  }
  return std::nullopt;
}

}  // namespace pvr::proto
