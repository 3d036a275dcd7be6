#include "dispatch.h"

#include <mpi.h>
#include <unistd.h>

#include <chrono>
#include <cstring>

namespace pvr::runtime {

namespace {

// Commands travel on a duplicate of MPI_COMM_WORLD so that they never match
// the messages and collectives of the actions themselves.
MPI_Comm commandComm() {
  static MPI_Comm comm = [] {
    MPI_Comm c;
    MPI_Comm_dup(MPI_COMM_WORLD, &c);
    return c;
  }();
  return comm;
}

struct CommandHeader {
  std::int32_t action = -1;
  std::uint32_t argsBytes = 0;
};

// Waits for a non-blocking request: spins briefly (an action's next step
// usually follows at once), then sleeps between tests.
void waitPolitely(MPI_Request& request) {
  int done = 0;
  for (int spin = 0; spin < 2000 && !done; ++spin) MPI_Test(&request, &done, MPI_STATUS_IGNORE);
  while (!done) {
    ::usleep(500);
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
  }
}

std::optional<RankFailure> runLocal(NodeState& state, int index, const ActionArgs& args) {
  std::optional<RankFailure> mine;
  try {
    actionTable()[std::size_t(index)].run(state, args);
  } catch (...) {
    mine = failureOf(std::current_exception(), state.world.rank());
  }
  return agreeOn(state.world, mine);
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

void checkActionTables(composite::Communicator& world) {
  const std::uint64_t mine = actionTableHash();
  composite::Bytes bytes(sizeof mine);
  std::memcpy(bytes.data(), &mine, sizeof mine);
  const std::vector<composite::Bytes> all = world.allGather(bytes);
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

std::optional<RankFailure> invoke(NodeState& state, std::string_view name, const ActionArgs& args,
                                  double* broadcastSeconds) {
  const int index = actionIndex(name);
  if (index < 0) throw Error(ErrorCode::kInternal, "no action named " + std::string(name));
  const auto start = std::chrono::steady_clock::now();
  const std::string text = args.is_null() ? std::string() : args.dump();
  CommandHeader header{index, std::uint32_t(text.size())};
  // Slaves wait in MPI_Ibcast; a non-blocking collective matches only another.
  MPI_Request request;
  MPI_Ibcast(&header, sizeof header, MPI_BYTE, 0, commandComm(), &request);
  MPI_Wait(&request, MPI_STATUS_IGNORE);
  if (!text.empty()) MPI_Bcast(const_cast<char*>(text.data()), int(text.size()), MPI_CHAR, 0, commandComm());
  if (broadcastSeconds)
    *broadcastSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return runLocal(state, index, args);
}

void serveSlave(NodeState& state) {
  while (state.running) {
    CommandHeader header;
    MPI_Request request;
    MPI_Ibcast(&header, sizeof header, MPI_BYTE, 0, commandComm(), &request);
    waitPolitely(request);
    std::string text(header.argsBytes, '\0');
    if (!text.empty()) MPI_Bcast(text.data(), int(text.size()), MPI_CHAR, 0, commandComm());
    if (header.action < 0 || std::size_t(header.action) >= actionTable().size()) {
      // Same table hash on every rank, so this is a broken transport.
      std::fprintf(stderr, "pvr-node: rank %d: command %d out of the action table\n", state.world.rank(), header.action);
      MPI_Abort(MPI_COMM_WORLD, 1);
    }
    runLocal(state, header.action, text.empty() ? ActionArgs() : ActionArgs::parse(text));
  }
}

}  // namespace pvr::runtime
