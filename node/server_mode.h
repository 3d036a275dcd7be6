// pvr-node --server: the long-lived MPI job of a pvrd session.
//
// Rank 0, the master, connects back to the session handler, reads protocol
// messages and turns each into action-table calls (dispatch.h, actions/)
// that every rank runs; the other ranks run nothing but those actions.
// Rank 0 is also the collector that sends frames to the client in order.
#pragma once

#include <string>

namespace pvr::node {

struct ServerOptions {
  std::string host;     // the session handler's listening socket
  int port = 0;
  std::string dataDir;  // datasets must resolve inside it
  // Tests: "ACTION@RANK" makes ACTION throw once on that world rank.
  std::string failOnce;
  // Tests: the collector also writes every frame as linear premultiplied
  // float RGBA (frame-REQUEST-N.f32: i32 width, i32 height, pixels) here.
  std::string dumpFrames;
};

// Parses "--server --connect HOST:PORT --data-dir DIR [--fail-once A@R]
// [--dump-frames DIR]"; false and `error` on a bad command line.
bool parseServerOptions(int argc, char** argv, ServerOptions& options, std::string& error);

// Runs the session on every rank (MPI is initialised); returns the exit
// status when the session ends.
int runServer(const ServerOptions& options);

}  // namespace pvr::node
