// Hand-built frames for hostile-input tests: any header field, any payload.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <vector>

#include "byte_io.h"
#include "pvr_protocol.h"

namespace pvr::proto::testing {

struct RawHeader {
  std::uint8_t type = Hello::kWire.type;
  std::uint8_t version = kProtocolVersion;
  std::uint16_t flags = 0;
  std::uint32_t requestId = 1;
  // Length written in the header; by default the payload's true size.
  std::int64_t payloadBytes = -1;
};

inline std::vector<std::uint8_t> rawFrame(const RawHeader& raw, const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> frame(kHeaderBytes);
  const FrameHeader header{raw.version, raw.type, raw.flags, raw.requestId,
                           raw.payloadBytes < 0 ? static_cast<std::uint32_t>(payload.size())
                                                : static_cast<std::uint32_t>(raw.payloadBytes)};
  writeHeader(header, std::span(frame).first<kHeaderBytes>());
  frame.insert(frame.end(), payload.begin(), payload.end());
  return frame;
}

// Little-endian payload bytes from a list of typed pieces:
//   payload([](ByteWriter& w) { w.integer<std::uint32_t>(3); w.raw(...); })
template <class F>
std::vector<std::uint8_t> payload(F&& write) {
  std::vector<std::uint8_t> bytes;
  ByteWriter writer(bytes);
  write(writer);
  return bytes;
}

inline std::vector<std::uint8_t> textBytes(const char* text) {
  std::vector<std::uint8_t> bytes;
  for (const char* p = text; *p; ++p) bytes.push_back(static_cast<std::uint8_t>(*p));
  return bytes;
}

}  // namespace pvr::proto::testing
