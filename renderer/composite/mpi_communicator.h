// The Communicator over MPI: the one file of pvr::composite that includes
// mpi.h (this header does not, so callers compile without MPI's flags).
//
// MpiEnvironment initialises MPI for the life of the object and hands out
// the communicator of MPI_COMM_WORLD. Errors of MPI itself abort the job
// (MPI_ERRORS_ARE_FATAL): a broken transport is not a user error.
// A message must stay under 2 GiB (MPI counts are int); larger throws.
#pragma once

#include <memory>

#include "communicator.h"

namespace pvr::composite {

class MpiEnvironment {
 public:
  MpiEnvironment(int* argc, char*** argv);
  ~MpiEnvironment();
  MpiEnvironment(const MpiEnvironment&) = delete;
  MpiEnvironment& operator=(const MpiEnvironment&) = delete;

  Communicator& world();

 private:
  std::unique_ptr<Communicator> world_;
};

}  // namespace pvr::composite
