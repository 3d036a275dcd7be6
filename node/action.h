// Actions: what the master asks every rank to do (dispatch.h runs them).
//
// An action is a struct that names itself, lists its argument fields for
// the protocol's field codec (protocol/field_codec.h) and declares the
// function every rank runs with them:
//
//   struct ReportMemory {
//     static constexpr std::string_view kName = "report_memory";
//     std::int32_t cluster = -1;
//     static auto fields(auto& self) { return std::tie(self.cluster); }
//     static void run(NodeState& state, const ReportMemory& args);
//   };
//
// The master encodes the arguments once and runs the action with the
// struct it has; every other rank decodes them once into the same struct.
// ActionList<A...> (the list is actions/table.h) gives each action the
// index commands carry and the table the slaves run from.
#pragma once

#include <concepts>
#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "field_codec.h"
#include "node.h"

namespace pvr::node {

template <class A>
concept Action = proto::WireStruct<A> && requires(NodeState& state, const A& args) {
  { A::kName } -> std::convertible_to<std::string_view>;
  A::run(state, args);
};

// One row of the table the slaves run from.
struct ActionEntry {
  std::string_view name;
  // Decodes the argument bytes into the action's struct and runs it.
  void (*decodeAndRun)(NodeState& state, std::span<const std::uint8_t> arguments);
};

template <Action A>
std::vector<std::uint8_t> encodeArguments(const A& args) {
  std::vector<std::uint8_t> bytes;
  proto::ByteWriter writer(bytes);
  proto::writeField(writer, args);
  return bytes;
}

template <Action A>
void decodeAndRun(NodeState& state, std::span<const std::uint8_t> arguments) {
  proto::ByteReader reader(arguments, "arguments of action " + std::string(A::kName));
  A args;
  proto::readField(reader, args);
  reader.expectEnd();
  if (!reader.ok()) {
    // Every rank checked at start that it has the master's table, so bytes
    // that do not decode are a broken transport, and this rank cannot take
    // part in the action's collectives: the job ends.
    std::fprintf(stderr, "pvr-node: rank %d: %s\n", state.world.rank(), reader.error()->text.c_str());
    state.commands.abortJob(1);
  }
  A::run(state, args);
}

template <Action... A>
struct ActionList {
  // The position of B in the list: the index its commands carry.
  template <class B>
  static constexpr int indexOf() {
    constexpr bool same[] = {std::is_same_v<A, B>...};
    for (int i = 0; i < int(sizeof...(A)); ++i)
      if (same[i]) return i;
    return -1;
  }
  static const std::vector<ActionEntry>& entries() {
    static const std::vector<ActionEntry> table{{A::kName, &decodeAndRun<A>}...};
    return table;
  }
};

}  // namespace pvr::node
