// The fixed 16-byte frame header and the size limits a receiver enforces.
//
// Every message travels as one frame: this header, then `payloadBytes` bytes
// of payload. All integers are little-endian. Byte layout (docs/protocol.md):
//
//   offset size field
//        0    4 magic          0x89 'P' 'V' 'R'
//        4    1 version        kProtocolVersion
//        5    1 type           message type (message_table.h)
//        6    2 flags          kFlagFinal; the other bits are reserved, zero
//        8    4 request id     chosen by the client, echoed by answers
//       12    4 payload bytes  length of the payload that follows
//
// The magic opens with a byte that is not ASCII, so a text client (telnet,
// HTTP) is refused at the first byte, as PNG does.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace pvr::proto {

inline constexpr std::array<std::uint8_t, 4> kMagic{0x89, 'P', 'V', 'R'};
inline constexpr std::uint8_t kProtocolVersion = 1;
inline constexpr std::size_t kHeaderBytes = 16;

// Set on the last message that answers a request id: the last ImageFrame of
// a rotation, an Ok, an Error, a reply. A client retires the request then.
inline constexpr std::uint16_t kFlagFinal = 0x0001;
inline constexpr std::uint16_t kKnownFlags = kFlagFinal;

// Largest frame (header + payload) a receiver accepts by default: an
// uncompressed 4096 x 4096 RGB image fits (proto::checkImageSize decides
// which image sizes do).
inline constexpr std::uint32_t kMaxFrameBytes = 64u << 20;

// Wire bytes of the FrameTiming record: seven f64 phases
// (protocol_messages.h checks the struct against it).
inline constexpr std::uint32_t kFrameTimingBytes = 7 * 8;

// The most frames one RenderRotation or RenderTimeSteps may ask for.
inline constexpr std::uint32_t kMaxRotationFrames = 100000;

// Receiver-side limits, checked against the header before any payload byte
// is buffered or any allocation is sized. Each message type names the field
// that bounds its payload (message_table.h); every payload is also bounded
// by maxFrameBytes - kHeaderBytes.
struct Limits {
  std::uint32_t maxFrameBytes = kMaxFrameBytes;  // any frame; bounds image frames
  std::uint32_t maxControlPayload = 64u << 10;   // hello, auth, session, render, ...
  std::uint32_t maxTextPayload = 4u << 20;       // scene JSON, status, catalog, performance
  std::uint64_t maxImagePixels = 8192ull * 8192ull;  // width * height of an ImageFrame
  std::uint32_t maxRotationFrames = kMaxRotationFrames;  // frames of one RenderRotation or RenderTimeSteps
};

struct FrameHeader {
  std::uint8_t version = kProtocolVersion;
  std::uint8_t type = 0;
  std::uint16_t flags = 0;
  std::uint32_t requestId = 0;
  std::uint32_t payloadBytes = 0;

  bool operator==(const FrameHeader&) const = default;
};

// Writes the 16 header bytes (magic included) to `out`.
void writeHeader(const FrameHeader& header, std::span<std::uint8_t, kHeaderBytes> out);

// Reads the fields of 16 header bytes; checks nothing (frame_codec.h does).
FrameHeader readHeader(std::span<const std::uint8_t, kHeaderBytes> bytes);

// True when the first min(4, bytes.size()) bytes agree with kMagic, so a
// wrong magic is refused at its first wrong byte.
bool magicPrefixMatches(std::span<const std::uint8_t> bytes);

}  // namespace pvr::proto
