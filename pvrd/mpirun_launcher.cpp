#include "mpirun_launcher.h"

#include <netdb.h>
#include <sys/socket.h>

#include <regex>

#include "pvr_protocol.h"

namespace pvr::daemon {
namespace {

constexpr std::size_t kTailInText = 600;

// The name the resolver gives an IPv4 or IPv6 address (the hosts file of a
// cluster names its nodes), or the address itself.
std::string hostNameOf(const std::string& address) {
  addrinfo hints{};
  hints.ai_flags = AI_NUMERICHOST;  // an address, never a lookup by name
  addrinfo* found = nullptr;
  if (::getaddrinfo(address.c_str(), nullptr, &hints, &found) != 0) return address;
  char name[NI_MAXHOST];
  const int rc = ::getnameinfo(found->ai_addr, found->ai_addrlen, name, sizeof name, nullptr, 0, NI_NAMEREQD);
  ::freeaddrinfo(found);
  return rc == 0 ? std::string(name) : address;
}

class MpirunLauncher final : public Launcher {
 public:
  explicit MpirunLauncher(const DaemonOptions& options) : Launcher(options) {}
  std::string_view program() const override { return "mpirun"; }
  std::string endText(const std::string& why) const override { return mpirunEndText(why, process_.tail()); }

 private:
  std::vector<std::string> command(const JobSpec& spec) const override {
    return mpirunCommand(spec, options_, true);
  }
};

}  // namespace

std::unique_ptr<Launcher> makeMpirunLauncher(const DaemonOptions& options) {
  return std::make_unique<MpirunLauncher>(options);
}

std::vector<std::string> mpirunCommand(const JobSpec& spec, const DaemonOptions& options, bool withHostfile) {
  std::vector<std::string> args{options.mpirun, "--oversubscribe", "--bind-to", "none", "-np", std::to_string(spec.ranks)};
  if (withHostfile && !options.hostfile.empty()) args.insert(args.end(), {"--hostfile", options.hostfile});
  // -x hands the variable to every rank, rank 0 included, wherever it runs.
  args.insert(args.end(), {"-x", proto::kJobSecretVariable, spec.nodePath, "--server", "--connect", spec.connect, "--data-dir",
                           spec.dataDir, "--stall-timeout", std::to_string(options.stallTimeout)});
  return args;
}

int rankFromMpirunOutput(const std::string& text) {
  static const std::regex re(R"(rank\s+(\d+))", std::regex::icase);
  std::smatch m;
  if (std::regex_search(text, m, re)) return std::stoi(m[1].str());
  return -1;
}

std::string lostHostFromMpirunOutput(const std::string& text) {
  // Open MPI 4.1 names the host whose daemon it lost ("Remote daemon:
  // [[...],2] on node h2") or whose peer went away ("Peer host: h2"), or,
  // when a rank finds the lost host's ranks unreachable first, its address
  // ("connect() to 10.213.7.12:1024 failed"), or, when the ssh that runs
  // the host's daemon notices first, ssh's own words ("Connection to
  // 10.213.7.12 closed by remote host.", then a generic ORTE block).
  static const std::regex daemon(R"(Remote daemon:[^\n]*on node\s+([^\s]+))");
  static const std::regex peer(R"(Peer host:\s*([^\s]+))");
  static const std::regex unreachable(R"(connect\(\) to \[?([0-9A-Fa-f.:]+?)\]?:[0-9]+ failed)");
  static const std::regex sshClosed(R"(Connection to ([^\s]+) closed by remote host)");
  std::smatch m;
  if (std::regex_search(text, m, daemon) || std::regex_search(text, m, peer)) return m[1].str();
  if (std::regex_search(text, m, unreachable) || std::regex_search(text, m, sshClosed)) return hostNameOf(m[1].str());
  return {};
}

std::string mpirunEndText(const std::string& why, const std::string& outputTail) {
  const std::string host = lostHostFromMpirunOutput(outputTail);
  if (!host.empty())
    return "host " + host + " was lost: Open MPI lost contact with it and ended the rendering job (" + why + ")";
  const int rank = rankFromMpirunOutput(outputTail);
  if (rank >= 0) return "rank " + std::to_string(rank) + " failed: the rendering job ended (" + why + ")";
  const std::string tail =
      outputTail.size() > kTailInText ? outputTail.substr(outputTail.size() - kTailInText) : outputTail;
  return "the rendering job ended unexpectedly (" + why + "): " + tail;
}

}  // namespace pvr::daemon
