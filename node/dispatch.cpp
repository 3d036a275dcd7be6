#include "dispatch.h"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>

namespace pvr::node {

namespace {

// Runs `action` on this rank, then agrees with every other rank.
std::optional<comm::Failure> runAgreeing(NodeState& state, const std::function<void()>& action) {
  std::optional<comm::Failure> mine;
  if (state.liveness) ++state.liveness->progress;  // an action started: this rank is not hung
  try {
    action();
  } catch (...) {
    mine = comm::failureOf(std::current_exception(), state.world.rank());
  }
  return state.world.agree(mine);
}

// FNV-1a over "index:name;" of every entry.
std::uint64_t actionTableHash() {
  std::uint64_t h = 1469598103934665603ull;
  const auto mix = [&](std::string_view s) {
    for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  };
  const auto& table = ActionTable::entries();
  for (std::size_t i = 0; i < table.size(); ++i) {
    mix(std::to_string(i));
    mix(":");
    mix(table[i].name);
    mix(";");
  }
  return h;
}

}  // namespace

void checkActionTables(comm::Communicator& world) {
  const std::uint64_t mine = actionTableHash();
  comm::Bytes bytes(sizeof mine);
  std::memcpy(bytes.data(), &mine, sizeof mine);
  const std::vector<comm::Bytes> all = world.allGather(bytes);
  std::uint64_t master = 0;
  std::memcpy(&master, all[0].data(), sizeof master);
  for (std::size_t r = 1; r < all.size(); ++r) {
    std::uint64_t theirs = 0;
    std::memcpy(&theirs, all[r].data(), sizeof theirs);
    if (theirs != master) {
      char text[200];
      std::snprintf(text, sizeof text,
                    "action table mismatch: rank %zu has table hash %016llx, rank 0 has %016llx "
                    "(different pvr-node builds in one job)",
                    r, static_cast<unsigned long long>(theirs), static_cast<unsigned long long>(master));
      throw Error(ErrorCode::kInternal, text);
    }
  }
}

std::optional<comm::Failure> postAndRun(NodeState& state, int index, std::span<const std::uint8_t> arguments,
                                        const std::function<void()>& runHere) {
  // A command: i32 action index, then the argument bytes.
  comm::Bytes command(4 + arguments.size());
  const std::int32_t i = index;
  std::memcpy(command.data(), &i, 4);
  std::memcpy(command.data() + 4, arguments.data(), arguments.size());
  const auto start = std::chrono::steady_clock::now();
  state.commands.post(command);
  state.commandSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return runAgreeing(state, runHere);
}

void serveSlave(NodeState& state) {
  const auto& table = ActionTable::entries();
  while (state.running) {
    const comm::Bytes command = state.commands.await();
    std::int32_t index = -1;
    if (command.size() >= 4) std::memcpy(&index, command.data(), 4);
    if (index < 0 || std::size_t(index) >= table.size()) {
      // Same table hash on every rank, so this is a broken transport.
      std::fprintf(stderr, "pvr-node: rank %d: command %d out of the action table\n", state.world.rank(), index);
      state.commands.abortJob(1);
    }
    const std::span<const std::uint8_t> arguments(reinterpret_cast<const std::uint8_t*>(command.data()) + 4,
                                                  command.size() - 4);
    runAgreeing(state, [&] { table[std::size_t(index)].decodeAndRun(state, arguments); });
  }
}

}  // namespace pvr::node
