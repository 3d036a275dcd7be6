#include "advertise.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "sys.h"

namespace pvr::daemon {

std::string firstHostfileHost(std::string_view text) {
  std::istringstream lines{std::string(text)};
  std::string line;
  while (std::getline(lines, line)) {
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    std::string host;
    if (!(words >> host)) continue;
    if (const auto at = host.find('@'); at != std::string::npos) host.erase(0, at + 1);
    return host;
  }
  return {};
}

std::string advertiseAddress(const DaemonOptions& options, std::string& error) {
  if (!options.advertise.empty()) return options.advertise;
  if (options.hostfile.empty()) return "127.0.0.1";
  std::ifstream in(options.hostfile);
  if (!in) {
    error = "cannot read hostfile " + options.hostfile + ": " + std::strerror(errno);
    return {};
  }
  std::ostringstream text;
  text << in.rdbuf();
  const std::string host = firstHostfileHost(text.str());
  if (host.empty()) {
    error = "hostfile " + options.hostfile + " names no host";
    return {};
  }
  std::string address = routeSourceAddress(host, error);
  if (address.empty())
    error = "no address to advertise towards " + host + ", the first host of " + options.hostfile + ": " + error +
            " (give --advertise ADDR)";
  return address;
}

}  // namespace pvr::daemon
