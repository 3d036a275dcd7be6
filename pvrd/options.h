// pvrd's command line: parsed into plain data, checked, no side effects.
#pragma once

#include <optional>
#include <string>
#include <vector>

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
  int stallTimeout = 30;        // seconds a rank may make no progress (pvr-node --stall-timeout)
};

// The command line, for the usage message.
inline constexpr const char* kUsage =
    "pvrd --listen HOST:PORT --data-dir DIR [--hostfile F] [--advertise ADDR] [--launcher mpirun|slurm] "
    "[--partition P] [--time T] [--max-ranks N] [--max-sessions N] [--token-file F] [--mpirun PATH] "
    "[--max-unauthenticated N] [--max-connections N] [--salloc PATH] [--scancel PATH] [--node PATH] "
    "[--idle-timeout S] [--frame-timeout S] [--handshake-timeout S] [--stall-timeout S]";

// Parses argv[1..]; on a bad command line returns nullopt and sets `error`.
std::optional<DaemonOptions> parseOptions(const std::vector<std::string>& args, std::string& error);

// True when `host` resolves, and only to loopback addresses (127.0.0.0/8,
// ::1): "localhost", "127.0.0.2", "::1"; not "127.attacker" (unless a
// resolver says it is loopback), not 0.0.0.0, not a name that fails.
bool isLoopback(const std::string& host);

}  // namespace pvr::daemon
