// The Communicator over MPI: mpi_communicator.cpp is the one file of the
// project that includes mpi.h (this header does not, so callers compile
// without MPI's flags).
//
// MpiEnvironment initialises MPI for the life of the object and hands out
// the communicator of MPI_COMM_WORLD, the master's command channel and,
// for a server, the watch threads' channel. Errors of MPI itself abort the job
// (MPI_ERRORS_ARE_FATAL): a broken transport is not a user error.
// A message must stay under 2 GiB (MPI counts are int); larger throws.
#pragma once

#include <memory>

#include "command_channel.h"
#include "communicator.h"
#include "liveness.h"
#include "watch_channel.h"

namespace pvr::comm {

class MpiEnvironment {
 public:
  // kMainOnly: only the main thread calls MPI (MPI_THREAD_FUNNELED).
  // kWatched: a watch thread calls the watch channel beside it
  // (MPI_THREAD_MULTIPLE); throws pvr::Error kUnsupported, naming the
  // level the library gives, when MPI cannot.
  enum class Threads { kMainOnly, kWatched };
  MpiEnvironment(int* argc, char*** argv, Threads threads = Threads::kMainOnly);
  ~MpiEnvironment();
  MpiEnvironment(const MpiEnvironment&) = delete;
  MpiEnvironment& operator=(const MpiEnvironment&) = delete;

  Communicator& world();
  // Commands from rank 0 on a duplicate of MPI_COMM_WORLD.
  CommandChannel& commands();
  // kWatched only (else null): the watch thread's channel.
  WatchChannel* watch();
  // Marked waiting by every blocking call of world() and commands().
  Liveness& liveness() { return liveness_; }

 private:
  Liveness liveness_;
  std::unique_ptr<Communicator> world_;
  std::unique_ptr<CommandChannel> commands_;
  std::unique_ptr<WatchChannel> watch_;
};

}  // namespace pvr::comm
