// FrameDecoder: the incremental, sans-IO side of a connection.
//
// Feed it whatever the socket delivered; pop decoded messages. It holds at
// most one unfinished frame, and only the bytes of it that have arrived: the
// header is checked (limits included) before any payload byte is kept, so a
// frame announcing 4 GiB fails after its 16 header bytes. The first protocol
// error is final: the owner replies with an Error and closes
// (docs/protocol.md, "Errors end the connection").
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <vector>

#include "frame_codec.h"

namespace pvr::proto {

class FrameDecoder {
 public:
  explicit FrameDecoder(const Limits& limits = {}) : limits_(limits) {}

  // Takes all of `bytes`. Complete frames queue for pop(); after an error
  // the rest of the input is dropped and later feeds do nothing.
  void feed(std::span<const std::uint8_t> bytes);

  // The oldest decoded message not yet popped. Messages decoded before an
  // error are still delivered.
  std::optional<Decoded> pop();

  // The first error, if any.
  const std::optional<ProtocolError>& error() const { return error_; }

  // The peer closed the stream: a frame begun but not finished becomes a
  // kTruncatedFrame error. Returns error().
  const std::optional<ProtocolError>& endOfStream();

  // Bytes of the unfinished frame held now (never more than that frame).
  std::size_t bufferedBytes() const { return partial_.size(); }

 private:
  Limits limits_;
  std::vector<std::uint8_t> partial_;
  std::deque<Decoded> ready_;
  std::optional<ProtocolError> error_;
};

}  // namespace pvr::proto
