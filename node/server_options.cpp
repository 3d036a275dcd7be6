#include "server_options.h"

#include <charconv>
#include <cmath>

#include "stall_limit.h"

namespace pvr::node {

namespace {

// A whole decimal integer, or false.
bool integer(const std::string& text, int& value) {
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  return ec == std::errc() && end == text.data() + text.size();
}

}  // namespace

bool parseServerOptions(int argc, char** argv, ServerOptions& options, std::string& error) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--server") continue;
    if (i + 1 >= argc) {
      error = a + " needs a value";
      return false;
    }
    const std::string v = argv[++i];
    if (a == "--connect") {
      const auto colon = v.rfind(':');
      if (colon == std::string::npos || !integer(v.substr(colon + 1), options.port)) {
        error = "--connect takes HOST:PORT, not '" + v + "'";
        return false;
      }
      options.host = v.substr(0, colon);
    } else if (a == "--data-dir") {
      options.dataDir = v;
    } else if (a == "--fail-once") {
      const auto at = v.find('@');
      int rank = -1;
      if (at == std::string::npos || !integer(v.substr(at + 1), rank) || rank < 0) {
        error = "--fail-once takes STEP@RANK, not '" + v + "'";
        return false;
      }
      options.injectedFailures.emplace_back(v.substr(0, at), rank);
    } else if (a == "--dump-frames") {
      options.dumpFrames = v;
    } else if (a == "--stall-timeout") {
      double seconds = 0;
      const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), seconds);
      if (ec != std::errc() || end != v.data() + v.size() || !std::isfinite(seconds) ||
          !proto::stallSecondsInRange(seconds)) {
        error = proto::stallTimeoutRefusal(v);
        return false;
      }
      options.stallSeconds = seconds;
    } else {
      error = "unknown option " + a;
      return false;
    }
  }
  if (options.host.empty() || options.port <= 0 || options.dataDir.empty()) {
    error = "server mode needs --connect HOST:PORT and --data-dir DIR";
    return false;
  }
  return true;
}

}  // namespace pvr::node
