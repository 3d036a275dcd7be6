#include "server_mode.h"

#include <atomic>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "dispatch.h"
#include "hosts.h"
#include "master.h"
#include "mpi_communicator.h"
#include "pvrd_link.h"
#include "pvrd_link_thread.h"
#include "rank_watch.h"

namespace pvr::node {

namespace {

// The one-time secret pvrd hands the job it launches (mpirun -x), which the
// master proves itself with on the connect-back (docs/runtime.md).

// The secret, taken out of this process's environment so that nothing this
// rank starts inherits it. Called before MPI starts its threads: unsetenv
// must not race with a getenv.
std::string takeJobSecret() {
  const char* value = std::getenv(proto::kJobSecretVariable);
  std::string secret = value ? value : "";
  ::unsetenv(proto::kJobSecretVariable);
  return secret;
}

}  // namespace

int runServer(const ServerOptions& options) {
  const std::string secret = takeJobSecret();
  // The watch thread calls MPI beside the main thread (rank_watch.h).
  std::unique_ptr<comm::MpiEnvironment> environment;
  try {
    environment = std::make_unique<comm::MpiEnvironment>(nullptr, nullptr, comm::MpiEnvironment::Threads::kWatched);
  } catch (const Error& e) {
    std::fprintf(stderr, "pvr-node: %s\n", e.what());
    return 1;
  }
  comm::MpiEnvironment& mpi = *environment;
  comm::Communicator& world = mpi.world();
  char real[PATH_MAX];
  NodeState state(world, mpi.commands(), ::realpath(options.dataDir.c_str(), real) ? real : "");
  state.injectedFailures = options.injectedFailures;
  state.dumpDir = options.dumpFrames;
  state.liveness = &mpi.liveness();

  std::unique_ptr<PvrdLink> link;
  if (world.rank() == 0) {
    try {
      // The secure channel keyed by the secret, then the first frame:
      // pvrd relays nothing until it has checked both.
      link = std::make_unique<PvrdLink>(options.host, options.port, secret);
      link->send(proto::JobHello{secret}, 0);
    } catch (const Error& e) {
      std::fprintf(stderr, "pvr-node: rank 0: %s\n", e.what());
      std::fflush(stderr);
      mpi.commands().abortJob(1);  // the other ranks wait for commands that will not come
    }
  }
  // Same table everywhere, or nobody starts.
  try {
    checkActionTables(world);
  } catch (const Error& e) {
    if (link) {
      link->send(proto::ErrorMessage{proto::ErrorCode::kInternal, e.what()}, 0);
      std::fprintf(stderr, "pvr-node: %s\n", e.what());
    }
    return 1;
  }
  state.hosts = gatherHostNames(world);
  const WatchOptions watchOptions{options.stallSeconds};
  if (world.rank() != 0) {
    RankWatch watch(*mpi.watch(), mpi.liveness(), watchOptions);
    state.watch = &watch;
    serveSlave(state);
    state.watch = nullptr;
    return 0;
  }

  // The link thread answers while frames render; the watch thread stops
  // the frames it cancels and ends the job when a rank stalls.
  std::atomic<RankWatch*> watching{nullptr};
  LinkThread linkThread(
      std::move(link), [&](std::uint32_t id) { if (RankWatch* w = watching.load()) w->cancel(id); }, &mpi.liveness());
  const auto stalled = [&](int rank, double seconds) {
    char text[400];
    std::snprintf(text, sizeof text, "rank %d on %s made no progress for %.0f s (stopped or hung); the job ends", rank,
                  state.hosts[std::size_t(rank)].c_str(), std::floor(seconds));
    std::fprintf(stderr, "pvr-node: %s\n", text);
    std::fflush(stderr);
    // The client hears why, then the link closes (pvrd ends the job); the
    // job ends itself too, as the main thread may wait on that rank for ever.
    linkThread.close(proto::ErrorMessage{proto::ErrorCode::kRankFailed, text});
    linkThread.waitClosed(5);
    mpi.commands().abortJob(1);
  };
  RankWatch watch(*mpi.watch(), mpi.liveness(), watchOptions, stalled);
  state.watch = &watch;
  watching = &watch;

  // The default layout (one render cluster of every rank) and the
  // compositing model's calibration; SessionOpen's layout follows.
  int status = 0;
  if (auto f = invoke(state, actions::SetLayout{})) {
    std::fprintf(stderr, "pvr-node: %s\n", describeOnHost(*f, state.hosts).c_str());
    status = 1;
  } else if (auto g = invoke(state, actions::Calibrate{})) {
    std::fprintf(stderr, "pvr-node: %s\n", describeOnHost(*g, state.hosts).c_str());
    status = 1;
  } else {
    Master(state, linkThread).serve();
  }
  invoke(state, actions::Shutdown{});
  watching = nullptr;
  state.watch = nullptr;
  return status;
}

}  // namespace pvr::node
