// FrameRelay: the pass-through side of a connection, for a hop that checks
// frames and forwards them as they came (pvrd, from the master rank to the
// client).
//
// Like FrameDecoder it takes whatever the socket delivered, checks each
// header (limits included) before it keeps any payload byte, and holds at
// most the one unfinished frame. A complete frame is checked exactly as
// decodeFrame checks it (same code, same text: checkPayload), but no
// message is built: an ImageFrame is checked from its fixed fields and its
// pixel byte count and its pixels are not copied again; the frame is handed
// out as the bytes that arrived.
//
// Unlike FrameDecoder it goes on after a frame it refuses when the frame's
// end is known: a payload over its limit is skipped by its announced length
// as it arrives (never buffered), a payload that fails its check is
// dropped, and each is reported as a RefusedFrame. Errors that leave the
// stream unsynchronised (magic, version, type, reserved flags) are final.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <variant>
#include <vector>

#include "frame_codec.h"

namespace pvr::proto {

// A checked frame, header included, byte for byte as it arrived.
struct RelayedFrame {
  FrameHeader header;
  const MessageInfo* info = nullptr;
  std::vector<std::uint8_t> bytes;
};

// A frame that failed its checks and was dropped; the stream goes on after it.
struct RefusedFrame {
  FrameHeader header;
  const MessageInfo* info = nullptr;
  ProtocolError error;  // kFrameTooLarge, or what decodeFrame would answer
};

using RelayItem = std::variant<RelayedFrame, RefusedFrame>;

class FrameRelay {
 public:
  explicit FrameRelay(const Limits& limits = {}) : limits_(limits) {}

  // Takes all of `bytes`. Frames and refusals queue for pop() in stream
  // order (a payload over its limit is refused as soon as its header is in);
  // after a final error the rest of the input is dropped.
  void feed(std::span<const std::uint8_t> bytes);

  std::optional<RelayItem> pop();

  // The first error that stopped the stream, if any.
  const std::optional<ProtocolError>& error() const { return error_; }

  // The peer closed the stream: a frame begun but not finished (or not yet
  // skipped to its end) becomes a kTruncatedFrame error. Returns error().
  const std::optional<ProtocolError>& endOfStream();

  // Bytes of the unfinished frame held now (a skipped payload holds none).
  std::size_t bufferedBytes() const { return partial_.size(); }

 private:
  void finishFrame();

  Limits limits_;
  std::vector<std::uint8_t> partial_;     // the unfinished frame, header first
  std::optional<CheckedHeader> header_;   // its header, once complete and checked
  std::uint64_t skipLeft_ = 0;            // payload bytes of a refused frame still to drop
  std::deque<RelayItem> ready_;
  std::optional<ProtocolError> error_;
};

}  // namespace pvr::proto
