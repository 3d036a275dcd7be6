// pvr-node-server: pvr-node's server mode as its own executable, launched by
// pvrd's session handler through mpirun.
#include <mpi.h>

#include <cstdio>

#include "server_mode.h"

int main(int argc, char** argv) {
  pvr::runtime::ServerOptions options;
  std::string error;
  if (!pvr::runtime::parseServerOptions(argc, argv, options, error)) {
    std::fprintf(stderr, "pvr-node-server: %s\n", error.c_str());
    return 2;
  }
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &options.rank);
  MPI_Comm_size(MPI_COMM_WORLD, &options.ranks);
  const int status = pvr::runtime::runServer(options);
  MPI_Finalize();
  return status;
}
