#include "options.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>

#include <charconv>

#include "launcher.h"
#include "stall_limit.h"

namespace pvr::daemon {
namespace {

bool toInt(const std::string& text, int lo, int hi, int& out) {
  int v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size() || v < lo || v > hi) return false;
  out = v;
  return true;
}

}  // namespace

bool isLoopback(const std::string& host) {
  // Decided on what the name resolves to, every address of it: a prefix
  // test took "127.attacker" for loopback, and such a name may resolve to
  // 0.0.0.0 (every interface).
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (host.empty() || ::getaddrinfo(host.c_str(), nullptr, &hints, &found) != 0) return false;
  bool loopback = found != nullptr;
  for (const addrinfo* a = found; a && loopback; a = a->ai_next) {
    if (a->ai_family == AF_INET) {
      const auto* v4 = reinterpret_cast<const sockaddr_in*>(a->ai_addr);
      loopback = (ntohl(v4->sin_addr.s_addr) >> 24) == 127;
    } else if (a->ai_family == AF_INET6) {
      const in6_addr& v6 = reinterpret_cast<const sockaddr_in6*>(a->ai_addr)->sin6_addr;
      loopback = IN6_IS_ADDR_LOOPBACK(&v6) || (IN6_IS_ADDR_V4MAPPED(&v6) && v6.s6_addr[12] == 127);
    } else {
      loopback = false;
    }
  }
  ::freeaddrinfo(found);
  return loopback;
}

std::optional<DaemonOptions> parseOptions(const std::vector<std::string>& args, std::string& error) {
  DaemonOptions o;
  // Help wins over everything else on the line, right or wrong.
  for (const std::string& a : args)
    if (a == "-h" || a == "--help") {
      o.help = true;
      return o;
    }
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (i + 1 >= args.size()) {
      error = a.rfind("--", 0) == 0 ? a + " needs a value" : "unexpected argument '" + a + "'";
      return std::nullopt;
    }
    const std::string& v = args[++i];
    if (a == "--listen") {
      const auto colon = v.rfind(':');
      if (colon == std::string::npos || colon == 0 || !toInt(v.substr(colon + 1), 0, 65535, o.port)) {
        error = "--listen takes HOST:PORT, not '" + v + "'";
        return std::nullopt;
      }
      o.host = v.substr(0, colon);
      if (o.host.size() > 2 && o.host.front() == '[' && o.host.back() == ']') o.host = o.host.substr(1, o.host.size() - 2);
    } else if (a == "--data-dir") {
      o.dataDir = v;
    } else if (a == "--hostfile") {
      o.hostfile = v;
    } else if (a == "--max-ranks" || a == "--max-sessions" || a == "--max-unauthenticated" ||
               a == "--max-connections") {
      int& target = a == "--max-ranks"            ? o.maxRanks
                    : a == "--max-sessions"       ? o.maxSessions
                    : a == "--max-unauthenticated" ? o.maxUnauthenticated
                                                   : o.maxConnections;
      if (!toInt(v, 1, 4096, target)) {
        error = a + " takes an integer in [1, 4096], not '" + v + "'";
        return std::nullopt;
      }
    } else if (a == "--token-file") {
      o.tokenFile = v;
    } else if (a == "--advertise") {
      in_addr parsed{};
      if (::inet_pton(AF_INET, v.c_str(), &parsed) != 1) {
        error = "--advertise takes a numeric IPv4 address, not '" + v + "'";
        return std::nullopt;
      }
      o.advertise = v;
    } else if (a == "--launcher") {
      if (!isLauncherName(v)) {
        error = "--launcher takes one of " + launcherNames() + ", not '" + v + "'";
        return std::nullopt;
      }
      o.launcher = v;
    } else if (a == "--partition" || a == "--time") {
      if (v.empty()) {
        error = a + " needs a value";
        return std::nullopt;
      }
      (a == "--partition" ? o.partition : o.time) = v;
    } else if (a == "--mpirun") {
      o.mpirun = v;
    } else if (a == "--salloc") {
      o.salloc = v;
    } else if (a == "--scancel") {
      o.scancel = v;
    } else if (a == "--node") {
      o.node = v;
    } else if (a == "--stall-timeout") {
      if (!toInt(v, proto::kMinStallSeconds, proto::kMaxStallSeconds, o.stallTimeout)) {
        error = proto::stallTimeoutRefusal(v);
        return std::nullopt;
      }
    } else if (a == "--idle-timeout" || a == "--frame-timeout" || a == "--handshake-timeout") {
      int s = 0;
      if (!toInt(v, 1, 1 << 30, s)) {
        error = a + " takes a positive number of seconds, not '" + v + "'";
        return std::nullopt;
      }
      (a == "--idle-timeout" ? o.idleTimeout : a == "--frame-timeout" ? o.frameTimeout : o.handshakeTimeout) = s;
    } else {
      error = "unknown option '" + a + "'";
      return std::nullopt;
    }
  }
  if (o.dataDir.empty()) {
    error = "--data-dir is required";
    return std::nullopt;
  }
  const bool slurm = o.launcher == "slurm";
  if (!slurm && (!o.partition.empty() || !o.time.empty())) {
    error = "--partition and --time need --launcher slurm";
    return std::nullopt;
  }
  if (slurm && !o.hostfile.empty()) {
    error = "--hostfile does not go with --launcher slurm: the allocation names the hosts";
    return std::nullopt;
  }
  if (!isLoopback(o.host) && o.tokenFile.empty()) {
    error = "refusing to listen on " + o.host + " without --token-file (see docs/pvrd.md)";
    return std::nullopt;
  }
  return o;
}

}  // namespace pvr::daemon
