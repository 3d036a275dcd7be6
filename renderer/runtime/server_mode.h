// pvr-node's server mode: the master rank connects back to the pvrd session
// handler and serves the protocol's session messages (Hello, Status,
// SetScene, RenderFrame, RenderRotation, Cancel, Close).
//
// This first version renders on the master alone with one BrickRenderer
// over the whole volume; the other ranks wait for the session to end.
#pragma once

#include <string>

namespace pvr::runtime {

struct ServerOptions {
  std::string host;     // the session handler's listening socket
  int port = 0;
  std::string dataDir;  // datasets must resolve inside it
  int rank = 0;
  int ranks = 1;
};

// Parses "--server --connect HOST:PORT --data-dir DIR"; false and `error`
// on a bad command line.
bool parseServerOptions(int argc, char** argv, ServerOptions& options, std::string& error);

// Runs the session on this rank; returns the process exit status. Every rank
// calls it (MPI is initialised); it returns on all ranks when the session ends.
int runServer(const ServerOptions& options);

}  // namespace pvr::runtime
