// The command line of pvr-node --server (docs/runtime.md).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "stall_limit.h"

namespace pvr::node {

struct ServerOptions {
  std::string host;     // the session handler's listening socket
  int port = 0;
  std::string dataDir;  // datasets must resolve inside it
  // Tests: each --fail-once STEP@RANK makes that step of a wave ("render"
  // or "composite") throw once on that world rank.
  std::vector<std::pair<std::string, int>> injectedFailures;
  // Tests: the collector also writes every frame as linear premultiplied
  // float RGBA (frame-REQUEST-N.f32: i32 width, i32 height, pixels) here.
  std::string dumpFrames;
  // A rank that makes no progress this long (four times as long while it
  // reads data) is reported by number and host, and the job ends
  // (rank_watch.h).
  double stallSeconds = proto::kDefaultStallSeconds;
};

// Parses "--server --connect HOST:PORT --data-dir DIR [--fail-once STEP@RANK]...
// [--dump-frames DIR] [--stall-timeout SECONDS]"; false and `error` on a bad command line.
bool parseServerOptions(int argc, char** argv, ServerOptions& options, std::string& error);

}  // namespace pvr::node
