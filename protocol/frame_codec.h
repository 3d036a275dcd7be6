// Encoding a message into one frame and decoding one frame from bytes.
//
// Both are pure functions over bytes. decodeFrame checks the header as far
// as bytes have arrived (a wrong magic is refused at its first wrong byte),
// checks the announced payload length against the limit for the message type
// before waiting for or buffering the payload, and then parses the payload
// with bounds checks.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <variant>
#include <vector>

#include "frame_header.h"
#include "message_table.h"
#include "protocol_error.h"
#include "protocol_messages.h"

namespace pvr::proto {

// Not enough bytes yet. `frameBytes` is the size the frame will have once
// known (header + payload), or kHeaderBytes while the header is incomplete.
struct NeedMore {
  std::size_t frameBytes = kHeaderBytes;
  bool operator==(const NeedMore&) const = default;
};

struct FrameInfo {
  std::uint32_t requestId = 0;
  std::uint16_t flags = 0;
  bool final() const { return (flags & kFlagFinal) != 0; }
  bool operator==(const FrameInfo&) const = default;
};

struct Decoded {
  Message message;
  FrameInfo info;
  std::size_t bytesConsumed = 0;  // header + payload
};

using DecodeResult = std::variant<NeedMore, Decoded, ProtocolError>;

// A header whose every field passed its check.
struct CheckedHeader {
  FrameHeader header;
  const MessageInfo* info = nullptr;
};

// Checks the header fields present in `prefix` (any length; bytes past the
// header are ignored): magic, version, type, reserved flags, then the payload
// length against payloadLimit() for that type (checkPayloadLength).
std::variant<NeedMore, CheckedHeader, ProtocolError> checkHeader(std::span<const std::uint8_t> prefix,
                                                                 const Limits& limits);

// The first four checks of checkHeader: after an error here the stream
// cannot be trusted any more.
std::variant<NeedMore, CheckedHeader, ProtocolError> checkHeaderFields(std::span<const std::uint8_t> prefix);

// The last check of checkHeader: kFrameTooLarge when the payload length is
// over payloadLimit() for the type. The frame's end is still known, so a
// relay may skip it and go on (frame_relay.h).
std::optional<ProtocolError> checkPayloadLength(const CheckedHeader& checked, const Limits& limits);

// Checks a whole payload of the checked header's type exactly as decodeFrame
// does (same code, same text) without keeping the message (MessageInfo::
// checkPayload: an ImageFrame's pixels are not copied).
std::optional<ProtocolError> checkPayload(const CheckedHeader& checked, std::span<const std::uint8_t> payload,
                                          const Limits& limits);

// One frame. Throws std::invalid_argument for reserved flag bits and
// std::length_error for a payload past 4 GiB - 1 bytes. It does not apply
// Limits: the receiver does.
std::vector<std::uint8_t> encode(const Message& message, std::uint32_t requestId, std::uint16_t flags = 0);

// The first frame in `bytes`; the bytes after it are left alone.
DecodeResult decodeFrame(std::span<const std::uint8_t> bytes, const Limits& limits = {});

}  // namespace pvr::proto
