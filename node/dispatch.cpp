#include "dispatch.h"

#include <chrono>
#include <cstring>

namespace pvr::node {

namespace {

// A command on the wire: i32 action index, then the argument bytes.
comm::Bytes encodeCommand(int index, const std::string& args) {
  comm::Bytes out(4 + args.size());
  const std::int32_t i = index;
  std::memcpy(out.data(), &i, 4);
  std::memcpy(out.data() + 4, args.data(), args.size());
  return out;
}

std::optional<comm::Failure> runLocal(NodeState& state, int index, const ActionArgs& args) {
  std::optional<comm::Failure> mine;
  try {
    actionTable()[std::size_t(index)].run(state, args);
  } catch (...) {
    mine = comm::failureOf(std::current_exception(), state.world.rank());
  }
  return state.world.agree(mine);
}

}  // namespace

void NodeState::matchPoolToSettings() {
  if (poolThreads == settings.threads) return;
  pool = std::make_unique<core::ThreadPool>(settings.threads);
  poolThreads = settings.threads;
}

void NodeState::maybeFail(const std::string& action) {
  if (action == failAction && world.rank() == failRank) {
    failAction.clear();
    throw Error(ErrorCode::kIo, "injected failure in action " + action);
  }
}

std::uint64_t actionTableHash() {
  // FNV-1a over "index:name;" of every entry.
  std::uint64_t h = 1469598103934665603ull;
  const auto mix = [&](std::string_view s) {
    for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  };
  for (std::size_t i = 0; i < actionTable().size(); ++i) {
    mix(std::to_string(i));
    mix(":");
    mix(actionTable()[i].name);
    mix(";");
  }
  return h;
}

int actionIndex(std::string_view name) {
  for (std::size_t i = 0; i < actionTable().size(); ++i)
    if (actionTable()[i].name == name) return int(i);
  return -1;
}

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

std::optional<comm::Failure> invoke(NodeState& state, std::string_view name, const ActionArgs& args,
                                  double* broadcastSeconds) {
  const int index = actionIndex(name);
  if (index < 0) throw Error(ErrorCode::kInternal, "no action named " + std::string(name));
  const auto start = std::chrono::steady_clock::now();
  const std::string text = args.is_null() ? std::string() : args.dump();
  state.commands.post(encodeCommand(index, text));
  if (broadcastSeconds)
    *broadcastSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return runLocal(state, index, args);
}

void serveSlave(NodeState& state) {
  while (state.running) {
    const comm::Bytes command = state.commands.await();
    std::int32_t index = -1;
    if (command.size() >= 4) std::memcpy(&index, command.data(), 4);
    if (index < 0 || std::size_t(index) >= actionTable().size()) {
      // Same table hash on every rank, so this is a broken transport.
      std::fprintf(stderr, "pvr-node: rank %d: command %d out of the action table\n", state.world.rank(), index);
      state.commands.abortJob(1);
    }
    const std::string text(reinterpret_cast<const char*>(command.data()) + 4, command.size() - 4);
    runLocal(state, index, text.empty() ? ActionArgs() : ActionArgs::parse(text));
  }
}

}  // namespace pvr::node
