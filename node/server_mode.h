// pvr-node --server: the long-lived MPI job of a pvrd session.
//
// Every rank takes PVR_JOB_SECRET out of its environment. Rank 0, the
// master, connects back to the session handler, proves with JobHello{that
// secret} that it is the job pvrd launched, and serves the client's
// requests (master.h), turning them into actions every rank runs
// (dispatch.h, actions/table.h); the other ranks run nothing but those
// actions. Rank 0 is also the collector that sends frames to the client
// in order.
#pragma once

#include "server_options.h"

namespace pvr::node {

// Runs the session on every rank (starts MPI); returns the exit status
// when the session ends.
int runServer(const ServerOptions& options);

}  // namespace pvr::node
