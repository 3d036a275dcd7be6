#include "frame_intake.h"

namespace pvr::tcl {

void FrameIntake::feed(std::span<const std::uint8_t> bytes) {
  if (error_) return;
  fed_ += bytes.size();
  relay_.feed(bytes);
  drainRelay();
}

void FrameIntake::drainRelay() {
  while (!error_) {
    auto item = relay_.pop();
    if (!item) break;
    ++framesEnded_;
    if (auto* frame = std::get_if<proto::RelayedFrame>(&*item)) {
      framed_ += frame->bytes.size();
      // The relay checked the frame exactly as decodeFrame does; decoding
      // it builds the message.
      auto decoded = proto::decodeFrame(frame->bytes, limits_);
      if (auto* d = std::get_if<proto::Decoded>(&decoded)) {
        ready_.push_back(std::move(*d));
      } else if (auto* e = std::get_if<proto::ProtocolError>(&decoded)) {
        error_ = std::move(*e);
      } else {
        error_ = proto::ProtocolError{proto::ErrorCode::kInternal, "a relayed frame did not decode whole"};
      }
      continue;
    }
    auto& refused = std::get<proto::RefusedFrame>(*item);
    framed_ += proto::kHeaderBytes + std::uint64_t{refused.header.payloadBytes};
    // Only a frame too large is skipped and survived: its bytes were never
    // kept. A payload that fails its checks means the server is broken.
    if (refused.error.code != proto::ErrorCode::kFrameTooLarge) {
      error_ = std::move(refused.error);
      break;
    }
    ready_.push_back(Refused{refused.header, refused.info ? refused.info->name : std::string_view("frame"),
                             std::move(refused.error)});
  }
  if (!error_ && relay_.error()) error_ = relay_.error();
}

std::optional<FrameIntake::Item> FrameIntake::pop() {
  if (ready_.empty()) return std::nullopt;
  Item item = std::move(ready_.front());
  ready_.pop_front();
  return item;
}

const std::optional<proto::ProtocolError>& FrameIntake::endOfStream() {
  if (!error_) {
    relay_.endOfStream();
    drainRelay();
    if (!error_ && relay_.error()) error_ = relay_.error();
  }
  return error_;
}

}  // namespace pvr::tcl
