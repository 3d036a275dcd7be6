// The Communicator over MPI: mpi_communicator.cpp is the one file of the
// project that includes mpi.h (this header does not, so callers compile
// without MPI's flags).
//
// MpiEnvironment initialises MPI for the life of the object and hands out
// the communicator of MPI_COMM_WORLD and the master's command channel. Errors of MPI itself abort the job
// (MPI_ERRORS_ARE_FATAL): a broken transport is not a user error.
// A message must stay under 2 GiB (MPI counts are int); larger throws.
#pragma once

#include <memory>

#include "command_channel.h"
#include "communicator.h"

namespace pvr::comm {

class MpiEnvironment {
 public:
  MpiEnvironment(int* argc, char*** argv);
  ~MpiEnvironment();
  MpiEnvironment(const MpiEnvironment&) = delete;
  MpiEnvironment& operator=(const MpiEnvironment&) = delete;

  Communicator& world();
  // Commands from rank 0 on a duplicate of MPI_COMM_WORLD.
  CommandChannel& commands();

 private:
  std::unique_ptr<Communicator> world_;
  std::unique_ptr<CommandChannel> commands_;
};

}  // namespace pvr::comm
