// pvrd's command line: parsed into plain data, checked, no side effects.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "stall_limit.h"

namespace pvr::daemon {

struct DaemonOptions {
  std::string host = "127.0.0.1";
  int port = 0;                 // 0: an ephemeral port
  std::string dataDir;
  std::string hostfile;         // passed to mpirun when set (launcher mpirun only)
  std::string advertise;        // numeric IPv4 the ranks reach the handler on; empty: advertise.h decides
  int maxRanks = 4;
  int maxSessions = 4;          // connections with a job (admission.h)
  int maxUnauthenticated = 8;   // connections still in their handshake
  int maxConnections = 64;      // handler processes in all
  std::string tokenFile;        // shared secret; required for a non-loopback address
  std::string launcher = "mpirun";  // a name of launcher.h's table
  std::string partition;        // slurm: salloc --partition; empty: the site's default
  std::string time;             // slurm: salloc --time; empty: the partition's default
  std::string mpirun = "mpirun";
  std::string salloc = "salloc";    // tests put a fake one here
  std::string scancel = "scancel";
  std::string node;             // pvr-node executable; empty: next to pvrd
  double idleTimeout = 600;     // seconds without a client frame
  double frameTimeout = 10;     // seconds to finish a frame once started
  double handshakeTimeout = 10; // seconds from accept to an authenticated Hello
  int stallTimeout = proto::kDefaultStallSeconds;  // a rank without progress (pvr-node --stall-timeout)
  bool help = false;            // -h or --help: print kUsage, nothing else
};

// The command line and every option, one line each: `pvrd --help` prints
// it, a bad command line prints its first line, and man/pvrd.1 follows it.
// Keep it beside parseOptions: an option added there is added here.
inline constexpr const char* kUsage =
    "usage: pvrd --listen HOST:PORT --data-dir DIR [OPTION VALUE ...]\n"
    "\n"
    "Serves pvrsh sessions: each connection gets a handler that starts an MPI job of pvr-node.\n"
    "\n"
    "options:\n"
    "  --listen HOST:PORT         address to listen on (port 0: any free port); required\n"
    "  --data-dir DIR             the datasets a session may load (its catalog); required\n"
    "  --hostfile F               Open MPI hostfile passed to mpirun (launcher mpirun)\n"
    "  --advertise ADDR           numeric IPv4 address the ranks connect back to\n"
    "  --launcher mpirun|slurm    how a job starts (default mpirun)\n"
    "  --partition P              slurm: salloc --partition\n"
    "  --time T                   slurm: salloc --time\n"
    "  --max-ranks N              most ranks one session may ask for (default 4)\n"
    "  --max-sessions N           sessions with a job at once (default 4)\n"
    "  --max-unauthenticated N    connections still in their handshake (default 8)\n"
    "  --max-connections N        handler processes in all (default 64)\n"
    "  --token-file F             shared secret; required to listen on a non-loopback address\n"
    "  --mpirun PATH              the mpirun to run (default mpirun)\n"
    "  --salloc PATH              the salloc to run (default salloc)\n"
    "  --scancel PATH             the scancel to run (default scancel)\n"
    "  --node PATH                the pvr-node executable (default: the one next to pvrd)\n"
    "  --idle-timeout S           seconds without a client message before a session ends (default 600)\n"
    "  --frame-timeout S          seconds to finish a frame once started (default 10)\n"
    "  --handshake-timeout S      seconds from accept to an authenticated hello (default 10)\n"
    "  --stall-timeout S          seconds a rank may make no progress before the job ends (default 30)\n"
    "  -h, --help                 print this help and exit\n"
    "\n"
    "example:\n"
    "  pvrd --listen 127.0.0.1:7350 --data-dir /data/volumes --max-ranks 4\n"
    "  pvrsh -nogui  (then: pvr_session :s; :s open 127.0.0.1:7350 -ranks 2)\n";

// Parses argv[1..]; on a bad command line returns nullopt and sets `error`.
std::optional<DaemonOptions> parseOptions(const std::vector<std::string>& args, std::string& error);

// True when `host` resolves, and only to loopback addresses (127.0.0.0/8,
// ::1): "localhost", "127.0.0.2", "::1"; not "127.attacker" (unless a
// resolver says it is loopback), not 0.0.0.0, not a name that fails.
bool isLoopback(const std::string& host);

}  // namespace pvr::daemon
