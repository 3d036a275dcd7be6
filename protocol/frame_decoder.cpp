#include "frame_decoder.h"

#include <algorithm>
#include <string>

#include "byte_io.h"

namespace pvr::proto {

void FrameDecoder::feed(std::span<const std::uint8_t> bytes) {
  while (!bytes.empty() && !error_) {
    // How many bytes the current frame needs in all: kHeaderBytes until the
    // header is complete, then header + payload.
    std::size_t frameBytes = kHeaderBytes;
    if (!partial_.empty()) {
      auto checked = checkHeader(partial_, limits_);
      if (auto* needMore = std::get_if<NeedMore>(&checked)) frameBytes = needMore->frameBytes;
      if (auto* header = std::get_if<CheckedHeader>(&checked)) {
        frameBytes = kHeaderBytes + header->header.payloadBytes;
      }
      const std::size_t take = std::min(frameBytes - partial_.size(), bytes.size());
      appendToFrame(partial_, bytes.first(take), frameBytes);
      bytes = bytes.subspan(take);
    }
    // With nothing held, decode straight from the input without copying.
    const std::span<const std::uint8_t> window = partial_.empty() ? bytes : std::span<const std::uint8_t>(partial_);
    DecodeResult result = decodeFrame(window, limits_);
    if (auto* decoded = std::get_if<Decoded>(&result)) {
      if (partial_.empty()) bytes = bytes.subspan(decoded->bytesConsumed);
      partial_.clear();
      ready_.push_back(std::move(*decoded));
    } else if (auto* error = std::get_if<ProtocolError>(&result)) {
      error_ = std::move(*error);
      partial_.clear();
    } else if (partial_.empty()) {
      // The input ends inside this frame: keep it (it is shorter than the
      // frame, whose header, if complete, passed the limits).
      appendToFrame(partial_, bytes, std::get<NeedMore>(result).frameBytes);
      bytes = {};
    }
  }
}

std::optional<Decoded> FrameDecoder::pop() {
  if (ready_.empty()) return std::nullopt;
  Decoded front = std::move(ready_.front());
  ready_.pop_front();
  return front;
}

const std::optional<ProtocolError>& FrameDecoder::endOfStream() {
  if (!error_ && !partial_.empty()) {
    error_ = ProtocolError{ErrorCode::kTruncatedFrame, "stream ended " + std::to_string(partial_.size()) +
                                                           " bytes into a frame"};
    partial_.clear();
  }
  return error_;
}

}  // namespace pvr::proto
