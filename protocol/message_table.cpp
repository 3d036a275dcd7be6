#include "message_table.h"

#include <algorithm>
#include <array>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "field_codec.h"

namespace pvr::proto {
namespace {

constexpr std::size_t kMessageCount = std::variant_size_v<Message>;

template <class T>
void encodeAs(const Message& message, ByteWriter& writer) {
  writeField(writer, std::get<T>(message));
}

template <class T>
Message decodeAs(ByteReader& reader, const Limits& limits) {
  T message{};
  readField(reader, message);
  reader.expectEnd();
  if constexpr (requires { message.check(limits); }) {
    if (reader.ok()) {
      if (auto problem = message.check(limits)) reader.fail(problem->code, std::move(problem->text));
    }
  }
  return message;
}

template <class T>
void checkAs(ByteReader& reader, const Limits& limits) {
  if constexpr (requires(T& m) { T::headFields(m); m.checkHead(std::uint64_t{0}, limits); }) {
    // The bulk field is a u32 byte count and the bytes (field_codec.h): the
    // count is checked against the bytes left as readField would, then the
    // bytes are stepped over.
    using Head = decltype(T::headFields(std::declval<T&>()));
    using All = decltype(T::fields(std::declval<T&>()));
    static_assert(std::tuple_size_v<All> == std::tuple_size_v<Head> + 1 &&
                      std::is_same_v<std::tuple_element_t<std::tuple_size_v<Head>, All>, std::vector<std::uint8_t>&>,
                  "fields() must be headFields() followed by one byte array");
    T message{};
    std::apply([&](auto&... field) { (readField(reader, field), ...); }, T::headFields(message));
    const std::uint32_t bulkBytes = reader.count(1, "byte array");
    reader.skip(bulkBytes);
    reader.expectEnd();
    if (reader.ok()) {
      if (auto problem = message.checkHead(bulkBytes, limits)) reader.fail(problem->code, std::move(problem->text));
    }
  } else {
    decodeAs<T>(reader, limits);
  }
}

template <std::size_t... I>
constexpr std::array<MessageInfo, kMessageCount> makeTable(std::index_sequence<I...>) {
  return {MessageInfo{std::variant_alternative_t<I, Message>::kWire.type,
                      std::variant_alternative_t<I, Message>::kWire.name,
                      std::variant_alternative_t<I, Message>::kWire.maxPayload, I,
                      &encodeAs<std::variant_alternative_t<I, Message>>,
                      &decodeAs<std::variant_alternative_t<I, Message>>,
                      &checkAs<std::variant_alternative_t<I, Message>>}...};
}

constexpr std::array<MessageInfo, kMessageCount> kTable = makeTable(std::make_index_sequence<kMessageCount>{});

// Wire type numbers must be non-zero and unique: a clash would make one
// message undecodable, so it is a compile error.
constexpr bool typesAreUnique() {
  for (std::size_t i = 0; i < kTable.size(); ++i) {
    if (kTable[i].type == 0) return false;
    for (std::size_t j = i + 1; j < kTable.size(); ++j) {
      if (kTable[i].type == kTable[j].type) return false;
    }
  }
  return true;
}
static_assert(typesAreUnique(), "two messages share a wire type number, or one uses 0");

constexpr std::array<const MessageInfo*, 256> makeByType() {
  std::array<const MessageInfo*, 256> byType{};
  for (const MessageInfo& info : kTable) byType[info.type] = &info;
  return byType;
}

constexpr std::array<const MessageInfo*, 256> kByType = makeByType();

}  // namespace

std::span<const MessageInfo> messageTable() { return kTable; }

const MessageInfo* findMessage(std::uint8_t type) { return kByType[type]; }

const MessageInfo& messageInfo(const Message& message) { return kTable[message.index()]; }

std::uint32_t payloadLimit(const MessageInfo& info, const Limits& limits) {
  const std::uint32_t frameRoom =
      limits.maxFrameBytes > kHeaderBytes ? limits.maxFrameBytes - static_cast<std::uint32_t>(kHeaderBytes) : 0;
  return std::min(limits.*info.maxPayload, frameRoom);
}

}  // namespace pvr::proto
