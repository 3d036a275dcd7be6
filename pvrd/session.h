// The session handler: one forked process per client connection. It does
// hello and authentication, answers catalog requests, launches the MPI job on
// SessionOpen, relays frames between the client and the master rank (the
// master's frames checked and passed on byte for byte, proto::FrameRelay),
// and tears the job down (its whole process group) when either side goes
// away.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "options.h"

namespace pvr::daemon {

struct SessionConfig {
  const DaemonOptions* options = nullptr;
  std::string token;      // empty: no authentication
  std::string nodePath;   // the pvr-node executable
  std::uint64_t id = 0;   // for log records
  std::vector<int> inherited;  // descriptors of the daemon the handler closes
};

// Serves `clientFd` until the session ends; returns the exit status for the
// handler process. Returns when the client leaves, the job dies, a protocol
// error ends the connection, or SIGTERM/SIGINT arrives (the handler installs
// them). The job is gone when it returns.
int runSession(const SessionConfig& config, int clientFd);

// The rank named in an mpirun error message ("... process rank 1 with PID ..."),
// or -1.
int rankFromMpirunStderr(const std::string& text);

}  // namespace pvr::daemon
