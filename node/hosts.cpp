#include "hosts.h"

#include <unistd.h>

#include <cctype>
#include <climits>
#include <span>

namespace pvr::node {

std::string hostName() {
  char name[HOST_NAME_MAX + 1] = {};
  if (::gethostname(name, sizeof name - 1) != 0 || name[0] == '\0') return "unknown-host";
  std::string out(name);
  for (char& c : out)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '.' && c != '_') c = '_';
  return out;
}

std::vector<std::string> gatherHostNames(comm::Communicator& world) {
  const std::string mine = hostName();
  std::vector<std::string> hosts;
  for (const comm::Bytes& b : world.allGather(std::as_bytes(std::span(mine.data(), mine.size()))))
    hosts.emplace_back(reinterpret_cast<const char*>(b.data()), b.size());
  return hosts;
}

std::string hostList(const std::vector<std::string>& hosts) {
  std::string out;
  for (const std::string& h : hosts) out += (out.empty() ? "" : " ") + h;
  return out;
}

std::string hostRuns(const std::vector<std::string>& hosts) {
  std::string out;
  for (std::size_t first = 0; first < hosts.size();) {
    std::size_t last = first;
    while (last + 1 < hosts.size() && hosts[last + 1] == hosts[first]) ++last;
    out += (out.empty() ? "" : ", ") + hosts[first] +
           (last == first ? " (rank " + std::to_string(first) + ")"
                          : " (ranks " + std::to_string(first) + "-" + std::to_string(last) + ")");
    first = last + 1;
  }
  return out;
}

std::string describeOnHost(const comm::Failure& failure, const std::vector<std::string>& hosts) {
  if (failure.origin < 0 || std::size_t(failure.origin) >= hosts.size()) return failure.describe();
  return "rank " + std::to_string(failure.origin) + " on " + hosts[std::size_t(failure.origin)] + ": " +
         failure.message;
}

}  // namespace pvr::node
