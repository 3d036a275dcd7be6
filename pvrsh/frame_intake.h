// FrameIntake: the bytes pvrd sends, as messages, for pvrsh's connection.
//
// Built on the protocol's FrameRelay, so a frame over its payload limit
// (a catalog over 4 MiB) is skipped by its announced length and reported
// as a Refused item while the stream goes on: the request it answered
// fails and the session serves on. Every other protocol error is final,
// as docs/protocol.md says ("Errors end the connection").
//
// It also knows whether a frame has begun and not ended (inFrame), which
// the connection's half-frame timer watches: a server that sends part of
// a frame and stops would otherwise hold the session for ever.
//
// Tcl-free and socket-free: the fuzzer (fuzz/pvrsh_messages_fuzz.cpp)
// compiles it as pvrsh does.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <string_view>
#include <variant>

#include "pvr_protocol.h"

namespace pvr::tcl {

class FrameIntake {
 public:
  // A frame refused whole (kFrameTooLarge); the frames after it still come.
  struct Refused {
    proto::FrameHeader header;  // request id, flags, announced payload bytes
    std::string_view type;      // "CatalogReply"
    proto::ProtocolError error; // the relay's text names the size and the limit
  };
  using Item = std::variant<proto::Decoded, Refused>;

  explicit FrameIntake(const proto::Limits& limits = {}) : limits_(limits), relay_(limits) {}

  // Takes all of `bytes`; whole frames and refusals queue for pop().
  void feed(std::span<const std::uint8_t> bytes);
  std::optional<Item> pop();

  // The error that ended the stream; items queued before it still pop.
  const std::optional<proto::ProtocolError>& error() const { return error_; }
  // The peer closed the stream: a frame begun and not ended is an error.
  const std::optional<proto::ProtocolError>& endOfStream();

  // A frame has begun (some of its bytes are in, or are still to be
  // skipped) and has not ended.
  bool inFrame() const { return fed_ != framed_; }
  // Frames ended so far (handed out or refused): a change means the frame
  // in progress now is a new one.
  std::uint64_t framesEnded() const { return framesEnded_; }

 private:
  void drainRelay();

  proto::Limits limits_;
  proto::FrameRelay relay_;
  std::deque<Item> ready_;
  std::optional<proto::ProtocolError> error_;
  std::uint64_t fed_ = 0;     // bytes fed
  std::uint64_t framed_ = 0;  // bytes of the frames the relay has handed out or refused
  std::uint64_t framesEnded_ = 0;
};

}  // namespace pvr::tcl
