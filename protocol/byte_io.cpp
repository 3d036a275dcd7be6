#include "byte_io.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace pvr::proto {

void ByteWriter::f64(double value) { integer(std::bit_cast<std::uint64_t>(value)); }

void ByteWriter::raw(std::span<const std::uint8_t> bytes) {
  out_.insert(out_.end(), bytes.begin(), bytes.end());
}

void ByteWriter::lengthPrefixed(std::span<const std::uint8_t> bytes) {
  count(bytes.size());
  raw(bytes);
}

void ByteWriter::count(std::size_t n) {
  if (n > std::numeric_limits<std::uint32_t>::max()) {
    throw std::length_error("pvr protocol: " + std::to_string(n) +
                            " elements do not fit a 32-bit length");
  }
  integer(static_cast<std::uint32_t>(n));
}

double ByteReader::f64() { return std::bit_cast<double>(integer<std::uint64_t>()); }

void ByteReader::raw(std::span<std::uint8_t> out) {
  if (!need(out.size(), "bytes")) return;
  if (!out.empty()) std::memcpy(out.data(), bytes_.data() + pos_, out.size());
  pos_ += out.size();
}

void ByteReader::skip(std::size_t n) {
  if (need(n, "bytes")) pos_ += n;
}

std::uint32_t ByteReader::count(std::size_t minElementBytes, const char* what) {
  const std::size_t at = pos_;
  const auto n = integer<std::uint32_t>();
  if (!ok()) return 0;
  // 64-bit product: n < 2^32 and minElementBytes is a small static size.
  const std::uint64_t wanted = std::uint64_t{n} * minElementBytes;
  if (wanted > remaining()) {
    fail(ErrorCode::kMalformedPayload,
         std::string(what) + " length " + std::to_string(n) + " at byte " + std::to_string(at) +
             " needs at least " + std::to_string(wanted) + " bytes but only " +
             std::to_string(remaining()) + " are left");
    return 0;
  }
  return n;
}

void ByteReader::fail(ErrorCode code, std::string text) {
  if (error_) return;
  error_ = ProtocolError{code, context_ + ": " + text};
}

void ByteReader::expectEnd() {
  if (ok() && remaining() != 0) {
    fail(ErrorCode::kMalformedPayload, std::to_string(remaining()) + " trailing bytes after byte " +
                                           std::to_string(pos_));
  }
}

bool ByteReader::need(std::size_t n, const char* what) {
  if (!ok()) return false;
  if (n > remaining()) {
    fail(ErrorCode::kMalformedPayload, std::string(what) + " of " + std::to_string(n) +
                                           " bytes at byte " + std::to_string(pos_) +
                                           " runs past the end (" + std::to_string(remaining()) +
                                           " bytes left)");
    return false;
  }
  return true;
}

void appendToFrame(std::vector<std::uint8_t>& buffer, std::span<const std::uint8_t> bytes, std::size_t frameBytes) {
  const std::size_t needed = buffer.size() + bytes.size();
  if (needed > buffer.capacity()) {
    buffer.reserve(std::min(frameBytes, std::max(needed, 2 * buffer.capacity())));
  }
  buffer.insert(buffer.end(), bytes.begin(), bytes.end());
}

}  // namespace pvr::proto
