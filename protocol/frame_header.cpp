#include "frame_header.h"

#include <algorithm>

namespace pvr::proto {
namespace {

void putLE(std::span<std::uint8_t> out, std::uint64_t value) {
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = static_cast<std::uint8_t>(value >> (8 * i));
}

std::uint64_t getLE(std::span<const std::uint8_t> in) {
  std::uint64_t value = 0;
  for (std::size_t i = 0; i < in.size(); ++i) value |= std::uint64_t{in[i]} << (8 * i);
  return value;
}

}  // namespace

void writeHeader(const FrameHeader& header, std::span<std::uint8_t, kHeaderBytes> out) {
  std::copy(kMagic.begin(), kMagic.end(), out.begin());
  out[4] = header.version;
  out[5] = header.type;
  putLE(out.subspan(6, 2), header.flags);
  putLE(out.subspan(8, 4), header.requestId);
  putLE(out.subspan(12, 4), header.payloadBytes);
}

FrameHeader readHeader(std::span<const std::uint8_t, kHeaderBytes> bytes) {
  FrameHeader header;
  header.version = bytes[4];
  header.type = bytes[5];
  header.flags = static_cast<std::uint16_t>(getLE(bytes.subspan(6, 2)));
  header.requestId = static_cast<std::uint32_t>(getLE(bytes.subspan(8, 4)));
  header.payloadBytes = static_cast<std::uint32_t>(getLE(bytes.subspan(12, 4)));
  return header;
}

bool magicPrefixMatches(std::span<const std::uint8_t> bytes) {
  const std::size_t n = std::min(bytes.size(), kMagic.size());
  return std::equal(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n), kMagic.begin());
}

}  // namespace pvr::proto
