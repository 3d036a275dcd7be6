// The look-up table from wire type numbers to message codecs, generated from
// the Message variant (protocol_messages.h), and the per-type payload limit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <type_traits>
#include <variant>

#include "byte_io.h"
#include "frame_header.h"
#include "protocol_messages.h"

namespace pvr::proto {

struct MessageInfo {
  std::uint8_t type = 0;
  std::string_view name;
  std::uint32_t Limits::*maxPayload = nullptr;
  std::size_t index = 0;  // alternative index in Message
  void (*encodePayload)(const Message& message, ByteWriter& writer) = nullptr;
  // Reads a whole payload (trailing bytes are an error) and applies check();
  // on failure the reader holds the error and the result is unspecified.
  Message (*decodePayload)(ByteReader& reader, const Limits& limits) = nullptr;
  // Fails the reader exactly where decodePayload would, keeping nothing: a
  // message with headFields (ImageFrame) is checked from its head fields and
  // bulk byte count, its bulk bytes skipped, not copied; others are decoded
  // and dropped.
  void (*checkPayload)(ByteReader& reader, const Limits& limits) = nullptr;
};

// One entry per alternative of Message, in variant order.
std::span<const MessageInfo> messageTable();

// The entry for a wire type number, or nullptr when this version has none.
const MessageInfo* findMessage(std::uint8_t type);

const MessageInfo& messageInfo(const Message& message);

// Largest payload a receiver accepts for `info`: its own limit, capped so the
// whole frame fits limits.maxFrameBytes.
std::uint32_t payloadLimit(const MessageInfo& info, const Limits& limits);

// Index of message type T in the Message variant.
template <class T, std::size_t I = 0>
constexpr std::size_t messageIndex() {
  static_assert(I < std::variant_size_v<Message>, "T is not a message type");
  if constexpr (std::is_same_v<T, std::variant_alternative_t<I, Message>>) {
    return I;
  } else {
    return messageIndex<T, I + 1>();
  }
}

}  // namespace pvr::proto
