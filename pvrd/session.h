// The session handler: one forked process per client connection. It does
// hello and authentication (within --handshake-timeout), takes a session
// slot from the daemon at SessionOpen (admission.h), answers catalog requests, launches the job on
// SessionOpen through the configured launcher (launcher.h), admits the
// master rank's connect-back only with the session's secret
// (connect_back.h), relays frames between the client and the master (the
// master's frames checked and passed on byte for byte, proto::FrameRelay),
// reports a batch queue's progress, and stops the job and releases its
// resources when either side goes away. It never blocks on one peer: both
// sockets are non-blocking, with bounded buffers (out_buffer.h), so a
// stopped master cannot keep it from seeing its client leave.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <string>
#include <vector>

#include "options.h"

namespace pvr::daemon {

struct SessionConfig {
  const DaemonOptions* options = nullptr;
  std::string token;      // empty: no authentication
  std::string nodePath;   // the pvr-node executable
  std::string advertise;  // the address the master connects back to (advertise.h)
  pid_t daemonPid = 0;    // names batch jobs: pvr-<daemonPid>-<id>
  std::uint64_t id = 0;   // for log records
  int admission = -1;     // the handler's end of its link to the daemon (admission.h); -1: none
  std::vector<int> inherited;  // descriptors of the daemon the handler closes
};

// Serves `clientFd` until the session ends; returns the exit status for the
// handler process. Returns when the client leaves, the job dies, a protocol
// error ends the connection, or SIGTERM/SIGINT arrives (the handler installs
// them). The job is gone and its allocation released when it returns.
int runSession(const SessionConfig& config, int clientFd);

}  // namespace pvr::daemon
