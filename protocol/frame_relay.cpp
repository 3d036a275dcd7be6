#include "frame_relay.h"

#include <algorithm>
#include <string>

#include "byte_io.h"

namespace pvr::proto {

void FrameRelay::feed(std::span<const std::uint8_t> bytes) {
  while (!error_) {
    // Step 1: drop the rest of a payload refused for its length.
    if (skipLeft_ > 0) {
      const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(skipLeft_, bytes.size()));
      skipLeft_ -= n;
      bytes = bytes.subspan(n);
      if (skipLeft_ > 0) return;
    }
    // Step 2: gather and check the header, field by field as bytes come.
    if (!header_) {
      if (bytes.empty()) return;
      const std::size_t take = std::min(kHeaderBytes - partial_.size(), bytes.size());
      appendToFrame(partial_, bytes.first(take), kHeaderBytes);
      bytes = bytes.subspan(take);
      auto checked = checkHeaderFields(partial_);
      if (auto* error = std::get_if<ProtocolError>(&checked)) {
        error_ = std::move(*error);
        partial_.clear();
        return;
      }
      if (std::holds_alternative<NeedMore>(checked)) continue;
      const auto& header = std::get<CheckedHeader>(checked);
      if (auto tooLarge = checkPayloadLength(header, limits_)) {
        ready_.push_back(RefusedFrame{header.header, header.info, std::move(*tooLarge)});
        skipLeft_ = header.header.payloadBytes;
        partial_.clear();
        continue;
      }
      header_ = header;
    }
    // Step 3: gather the payload; check and hand out the complete frame.
    const std::size_t frameBytes = kHeaderBytes + header_->header.payloadBytes;
    const std::size_t take = std::min(frameBytes - partial_.size(), bytes.size());
    appendToFrame(partial_, bytes.first(take), frameBytes);
    bytes = bytes.subspan(take);
    if (partial_.size() < frameBytes) return;
    finishFrame();
  }
}

void FrameRelay::finishFrame() {
  const CheckedHeader header = *header_;
  header_.reset();
  if (auto problem = checkPayload(header, std::span(partial_).subspan(kHeaderBytes), limits_)) {
    ready_.push_back(RefusedFrame{header.header, header.info, std::move(*problem)});
    partial_.clear();
    return;
  }
  ready_.push_back(RelayedFrame{header.header, header.info, std::move(partial_)});
  partial_ = {};
}

std::optional<RelayItem> FrameRelay::pop() {
  if (ready_.empty()) return std::nullopt;
  RelayItem front = std::move(ready_.front());
  ready_.pop_front();
  return front;
}

const std::optional<ProtocolError>& FrameRelay::endOfStream() {
  if (!error_ && (!partial_.empty() || skipLeft_ > 0)) {
    error_ = ProtocolError{ErrorCode::kTruncatedFrame,
                           partial_.empty() ? "stream ended " + std::to_string(skipLeft_) +
                                                  " bytes before the end of a refused frame"
                                            : "stream ended " + std::to_string(partial_.size()) +
                                                  " bytes into a frame"};
    partial_.clear();
    skipLeft_ = 0;
  }
  return error_;
}

}  // namespace pvr::proto
