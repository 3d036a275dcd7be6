#include "frame_codec.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include "byte_io.h"

namespace pvr::proto {
namespace {

std::string hexBytes(std::span<const std::uint8_t> bytes) {
  std::string text;
  for (std::uint8_t byte : bytes) {
    char digits[4];
    std::snprintf(digits, sizeof digits, "%02x", byte);
    if (!text.empty()) text += ' ';
    text += digits;
  }
  return text;
}

std::string hex(unsigned value, int width) {
  char digits[16];
  std::snprintf(digits, sizeof digits, "0x%0*x", width, value);
  return digits;
}

// "ImageFrame payload": how error texts name what they read.
std::string payloadContext(const MessageInfo& info) { return std::string(info.name) + " payload"; }

}  // namespace

std::variant<NeedMore, CheckedHeader, ProtocolError> checkHeaderFields(std::span<const std::uint8_t> prefix) {
  // Each field is checked as soon as its bytes are there.
  if (!magicPrefixMatches(prefix)) {
    const auto seen = prefix.first(std::min(prefix.size(), kMagic.size()));
    return ProtocolError{ErrorCode::kBadMagic, "bad magic: expected bytes " + hexBytes(kMagic) +
                                                   ", received " + hexBytes(seen)};
  }
  if (prefix.size() > 4 && prefix[4] != kProtocolVersion) {
    return ProtocolError{ErrorCode::kVersionMismatch, "version mismatch: peer speaks protocol version " +
                                                          std::to_string(prefix[4]) + ", this build speaks " +
                                                          std::to_string(kProtocolVersion)};
  }
  if (prefix.size() > 5 && findMessage(prefix[5]) == nullptr) {
    return ProtocolError{ErrorCode::kUnknownType, "unknown message type " + hex(prefix[5], 2)};
  }
  if (prefix.size() < kHeaderBytes) return NeedMore{kHeaderBytes};

  CheckedHeader checked{readHeader(prefix.first<kHeaderBytes>()), findMessage(prefix[5])};
  const FrameHeader& header = checked.header;
  if ((header.flags & ~kKnownFlags) != 0) {
    return ProtocolError{ErrorCode::kReservedFlags, "reserved flag bits " + hex(header.flags & ~kKnownFlags, 4) +
                                                        " set in a " + std::string(checked.info->name) + " header"};
  }
  return checked;
}

std::optional<ProtocolError> checkPayloadLength(const CheckedHeader& checked, const Limits& limits) {
  const std::uint32_t limit = payloadLimit(*checked.info, limits);
  if (checked.header.payloadBytes <= limit) return std::nullopt;
  return ProtocolError{ErrorCode::kFrameTooLarge, "frame too large: " + std::string(checked.info->name) +
                                                      " payload of " + std::to_string(checked.header.payloadBytes) +
                                                      " bytes exceeds the limit of " + std::to_string(limit) +
                                                      " bytes"};
}

std::variant<NeedMore, CheckedHeader, ProtocolError> checkHeader(std::span<const std::uint8_t> prefix,
                                                                 const Limits& limits) {
  auto checked = checkHeaderFields(prefix);
  if (const auto* header = std::get_if<CheckedHeader>(&checked)) {
    if (auto tooLarge = checkPayloadLength(*header, limits)) return std::move(*tooLarge);
  }
  return checked;
}

std::optional<ProtocolError> checkPayload(const CheckedHeader& checked, std::span<const std::uint8_t> payload,
                                          const Limits& limits) {
  ByteReader reader(payload, payloadContext(*checked.info));
  checked.info->checkPayload(reader, limits);
  return reader.error();
}

std::vector<std::uint8_t> encode(const Message& message, std::uint32_t requestId, std::uint16_t flags) {
  if ((flags & ~kKnownFlags) != 0) {
    throw std::invalid_argument("pvr protocol: reserved flag bits " + hex(flags & ~kKnownFlags, 4));
  }
  const MessageInfo& info = messageInfo(message);
  std::vector<std::uint8_t> frame(kHeaderBytes);
  ByteWriter writer(frame);
  info.encodePayload(message, writer);

  const std::size_t payloadBytes = frame.size() - kHeaderBytes;
  if (payloadBytes > std::numeric_limits<std::uint32_t>::max()) {
    throw std::length_error("pvr protocol: " + std::string(info.name) + " payload of " +
                            std::to_string(payloadBytes) + " bytes does not fit one frame");
  }
  const FrameHeader header{kProtocolVersion, info.type, flags, requestId, static_cast<std::uint32_t>(payloadBytes)};
  writeHeader(header, std::span(frame).first<kHeaderBytes>());
  return frame;
}

DecodeResult decodeFrame(std::span<const std::uint8_t> bytes, const Limits& limits) {
  auto checked = checkHeader(bytes, limits);
  if (auto* needMore = std::get_if<NeedMore>(&checked)) return *needMore;
  if (auto* error = std::get_if<ProtocolError>(&checked)) return std::move(*error);
  const auto& [header, info] = std::get<CheckedHeader>(checked);

  const std::size_t frameBytes = kHeaderBytes + header.payloadBytes;
  if (bytes.size() < frameBytes) return NeedMore{frameBytes};

  ByteReader reader(bytes.subspan(kHeaderBytes, header.payloadBytes), payloadContext(*info));
  Message message = info->decodePayload(reader, limits);
  if (!reader.ok()) return *reader.error();
  return Decoded{std::move(message), FrameInfo{header.requestId, header.flags}, frameBytes};
}

}  // namespace pvr::proto
