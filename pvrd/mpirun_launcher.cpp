#include "mpirun_launcher.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <sys/socket.h>

#include <cstring>
#include <regex>

#include "pvr_protocol.h"

namespace pvr::daemon {
namespace {

constexpr std::size_t kTailInText = 600;

// The name the resolver gives an IPv4 or IPv6 address (the hosts file of a
// cluster names its nodes), or the address itself.
std::string hostNameOf(const std::string& address) {
  sockaddr_storage storage{};
  socklen_t length = 0;
  auto* v4 = reinterpret_cast<sockaddr_in*>(&storage);
  auto* v6 = reinterpret_cast<sockaddr_in6*>(&storage);
  if (::inet_pton(AF_INET, address.c_str(), &v4->sin_addr) == 1) {
    v4->sin_family = AF_INET;
    length = sizeof *v4;
  } else if (::inet_pton(AF_INET6, address.c_str(), &v6->sin6_addr) == 1) {
    v6->sin6_family = AF_INET6;
    length = sizeof *v6;
  } else {
    return address;
  }
  char name[NI_MAXHOST];
  if (::getnameinfo(reinterpret_cast<sockaddr*>(&storage), length, name, sizeof name, nullptr, 0, NI_NAMEREQD) != 0)
    return address;
  return name;
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
                           spec.dataDir});
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
  // ("connect() to 10.213.7.12:1024 failed").
  static const std::regex daemon(R"(Remote daemon:[^\n]*on node\s+([^\s]+))");
  static const std::regex peer(R"(Peer host:\s*([^\s]+))");
  static const std::regex unreachable(R"(connect\(\) to \[?([0-9A-Fa-f.:]+?)\]?:[0-9]+ failed)");
  std::smatch m;
  if (std::regex_search(text, m, daemon) || std::regex_search(text, m, peer)) return m[1].str();
  if (std::regex_search(text, m, unreachable)) return hostNameOf(m[1].str());
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
