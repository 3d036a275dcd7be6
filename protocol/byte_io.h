// Little-endian byte writer and bounds-checked byte reader.
//
// ByteReader never reads past its span and never sizes anything from the
// bytes it reads without first checking the bytes are there. Its first
// failure is sticky: later reads return zeros and do not advance, so a
// decoder reads all its fields and asks ok() once at the end.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "protocol_error.h"

namespace pvr::proto {

class ByteWriter {
 public:
  explicit ByteWriter(std::vector<std::uint8_t>& out) : out_(out) {}

  template <class Int>
    requires std::is_integral_v<Int>
  void integer(Int value) {
    using U = std::make_unsigned_t<Int>;
    auto bits = static_cast<U>(value);
    for (std::size_t i = 0; i < sizeof(Int); ++i) {
      out_.push_back(static_cast<std::uint8_t>(bits >> (8 * i)));
    }
  }
  void f64(double value);
  void raw(std::span<const std::uint8_t> bytes);
  // u32 length, then the bytes. Throws std::length_error past 4 GiB - 1.
  void lengthPrefixed(std::span<const std::uint8_t> bytes);
  void count(std::size_t n);  // u32 element count; throws std::length_error past 4 GiB - 1

  std::size_t size() const { return out_.size(); }

 private:
  std::vector<std::uint8_t>& out_;
};

class ByteReader {
 public:
  // `context` names what is read ("ImageFrame payload") in error texts.
  ByteReader(std::span<const std::uint8_t> bytes, std::string context)
      : bytes_(bytes), context_(std::move(context)) {}

  template <class Int>
    requires std::is_integral_v<Int>
  Int integer() {
    if (!need(sizeof(Int), "integer")) return 0;
    using U = std::make_unsigned_t<Int>;
    U bits = 0;
    for (std::size_t i = 0; i < sizeof(Int); ++i) {
      bits = static_cast<U>(bits | static_cast<U>(static_cast<U>(bytes_[pos_ + i]) << (8 * i)));
    }
    pos_ += sizeof(Int);
    return static_cast<Int>(bits);
  }
  double f64();
  // Copies out.size() bytes; fails if fewer are left.
  void raw(std::span<std::uint8_t> out);
  // Steps over n bytes without reading them; fails if fewer are left.
  void skip(std::size_t n);
  // Reads a u32 element count and checks that `count * minElementBytes`
  // bytes are left before anyone allocates for them. Returns 0 on failure.
  std::uint32_t count(std::size_t minElementBytes, const char* what);

  // Records the first failure; later failures are ignored.
  void fail(ErrorCode code, std::string text);
  // Fails with kMalformedPayload unless every byte has been read.
  void expectEnd();

  bool ok() const { return !error_; }
  const std::optional<ProtocolError>& error() const { return error_; }
  std::size_t offset() const { return pos_; }
  std::size_t remaining() const { return bytes_.size() - pos_; }
  const std::string& context() const { return context_; }

 private:
  bool need(std::size_t n, const char* what);

  std::span<const std::uint8_t> bytes_;
  std::size_t pos_ = 0;
  std::string context_;
  std::optional<ProtocolError> error_;
};

// Appends `bytes` to `buffer` (an unfinished frame), growing its capacity
// with what has arrived, never past `frameBytes`, the frame's announced and
// already checked size: capacity follows the bytes received, not a length
// read off the wire.
void appendToFrame(std::vector<std::uint8_t>& buffer, std::span<const std::uint8_t> bytes, std::size_t frameBytes);

}  // namespace pvr::proto
