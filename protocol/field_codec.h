// Generic encoding of message fields, so each message lists its fields once.
//
// A wire struct declares its fields in wire order:
//
//   static auto fields(auto& self) { return std::tie(self.width, self.height); }
//
// and writeField/readField walk that list. Field types and their encoding:
//   bool                 u8, 0 or 1 (any other byte is malformed)
//   enum                 its underlying integer; isWireValue(e) must hold
//   integers             fixed width, little-endian
//   double               IEEE-754 binary64, little-endian bit pattern
//   std::string          u32 byte count, then the bytes
//   std::array<T, N>     N elements, no count
//   std::vector<T>       u32 element count, then the elements
//   wire struct          its fields in order
// A decoded value therefore re-encodes to the same bytes (the fuzz target
// relies on it).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "byte_io.h"

namespace pvr::proto {

template <class T>
concept WireStruct = requires(T& value) { T::fields(value); };

template <class T>
struct IsStdVector : std::false_type {};
template <class E, class A>
struct IsStdVector<std::vector<E, A>> : std::true_type {};

template <class T>
struct IsStdArray : std::false_type {};
template <class E, std::size_t N>
struct IsStdArray<std::array<E, N>> : std::true_type {};

// Fewest bytes a value of T occupies on the wire; bounds element counts
// against the bytes left before anything is allocated for them.
template <class T>
constexpr std::size_t minWireBytes();

template <class Tuple, std::size_t... I>
constexpr std::size_t minWireBytesOfFields(std::index_sequence<I...>) {
  return (std::size_t{0} + ... + minWireBytes<std::remove_cvref_t<std::tuple_element_t<I, Tuple>>>());
}

template <class T>
constexpr std::size_t minWireBytes() {
  if constexpr (std::is_arithmetic_v<T> || std::is_enum_v<T>) {
    return sizeof(T);
  } else if constexpr (std::is_same_v<T, std::string> || IsStdVector<T>::value) {
    return sizeof(std::uint32_t);
  } else if constexpr (IsStdArray<T>::value) {
    return std::tuple_size_v<T> * minWireBytes<typename T::value_type>();
  } else {
    static_assert(WireStruct<T>, "field type has no wire encoding");
    using Tuple = decltype(T::fields(std::declval<T&>()));
    return minWireBytesOfFields<Tuple>(std::make_index_sequence<std::tuple_size_v<Tuple>>{});
  }
}

template <class T>
void writeField(ByteWriter& writer, const T& value) {
  if constexpr (std::is_same_v<T, bool>) {
    writer.integer<std::uint8_t>(value ? 1 : 0);
  } else if constexpr (std::is_enum_v<T>) {
    writer.integer(static_cast<std::underlying_type_t<T>>(value));
  } else if constexpr (std::is_integral_v<T>) {
    writer.integer(value);
  } else if constexpr (std::is_same_v<T, double>) {
    writer.f64(value);
  } else if constexpr (std::is_same_v<T, std::string>) {
    writer.lengthPrefixed(std::span(reinterpret_cast<const std::uint8_t*>(value.data()), value.size()));
  } else if constexpr (IsStdArray<T>::value) {
    for (const auto& element : value) writeField(writer, element);
  } else if constexpr (std::is_same_v<T, std::vector<std::uint8_t>>) {
    writer.lengthPrefixed(value);
  } else if constexpr (IsStdVector<T>::value) {
    writer.count(value.size());
    for (const auto& element : value) writeField(writer, element);
  } else {
    static_assert(WireStruct<T>, "field type has no wire encoding");
    std::apply([&](const auto&... field) { (writeField(writer, field), ...); }, T::fields(value));
  }
}

template <class T>
void readField(ByteReader& reader, T& value) {
  if constexpr (std::is_same_v<T, bool>) {
    const std::size_t at = reader.offset();
    const auto byte = reader.integer<std::uint8_t>();
    if (byte > 1) {
      reader.fail(ErrorCode::kMalformedPayload,
                  "boolean at byte " + std::to_string(at) + " is " + std::to_string(byte) + ", not 0 or 1");
    }
    value = byte == 1;
  } else if constexpr (std::is_enum_v<T>) {
    const std::size_t at = reader.offset();
    const auto raw = reader.integer<std::underlying_type_t<T>>();
    value = static_cast<T>(raw);
    if (reader.ok() && !isWireValue(value)) {
      reader.fail(ErrorCode::kMalformedPayload, "enumeration value " + std::to_string(raw) + " at byte " +
                                                    std::to_string(at) + " is out of range");
    }
  } else if constexpr (std::is_integral_v<T>) {
    value = reader.integer<T>();
  } else if constexpr (std::is_same_v<T, double>) {
    value = reader.f64();
  } else if constexpr (std::is_same_v<T, std::string> || std::is_same_v<T, std::vector<std::uint8_t>>) {
    // The count is checked against the bytes left before the resize.
    value.resize(reader.count(1, std::is_same_v<T, std::string> ? "string" : "byte array"));
    reader.raw(std::span(reinterpret_cast<std::uint8_t*>(value.data()), value.size()));
  } else if constexpr (IsStdArray<T>::value) {
    for (auto& element : value) readField(reader, element);
  } else if constexpr (IsStdVector<T>::value) {
    using Element = typename T::value_type;
    static_assert(minWireBytes<Element>() > 0, "a list element must occupy at least one byte");
    const std::uint32_t n = reader.count(minWireBytes<Element>(), "list");
    value.clear();
    value.reserve(n);
    for (std::uint32_t i = 0; i < n && reader.ok(); ++i) readField(reader, value.emplace_back());
  } else {
    static_assert(WireStruct<T>, "field type has no wire encoding");
    std::apply([&](auto&... field) { (readField(reader, field), ...); }, T::fields(value));
  }
}

}  // namespace pvr::proto
