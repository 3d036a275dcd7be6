#include "catalog.h"

#include <poll.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "job_process.h"
#include "sys.h"

namespace pvr::daemon {
namespace {

namespace fs = std::filesystem;
using proto::ErrorCode;

std::string realPath(const std::string& path) {
  char buf[PATH_MAX];
  return ::realpath(path.c_str(), buf) ? std::string(buf) : std::string();
}

bool inside(const std::string& root, const std::string& path) {
  return !root.empty() && !path.empty() && path.size() > root.size() && path.compare(0, root.size(), root) == 0 &&
         (root == "/" || path[root.size()] == '/');
}

// A non-negative 32-bit decimal count, all of `text`.
bool parseCount(const std::string& text, std::uint32_t& out) {
  if (text.empty() || text.size() > 10) return false;
  std::uint64_t n = 0;
  for (char c : text) {
    if (c < '0' || c > '9') return false;
    n = n * 10 + std::uint64_t(c - '0');
  }
  if (n > UINT32_MAX) return false;
  out = std::uint32_t(n);
  return true;
}

// "STEPS<TAB>NAME<TAB>FILE<TAB>FORMAT<TAB>X<TAB>Y<TAB>Z<TAB>DTYPE<TAB>NOTE"
// with STEPS positive, as node/catalog_listing.cpp prints it.
bool parseEntry(const std::string& line, proto::CatalogEntry& entry) {
  std::vector<std::string> f;
  for (std::size_t at = 0;;) {
    const std::size_t tab = line.find('\t', at);
    f.push_back(line.substr(at, tab == std::string::npos ? std::string::npos : tab - at));
    if (tab == std::string::npos) break;
    at = tab + 1;
  }
  if (f.size() != 9 || f[1].empty() || f[2].empty()) return false;
  proto::CatalogEntry e;
  if (!parseCount(f[0], e.steps) || e.steps == 0) return false;
  for (int a = 0; a < 3; ++a)
    if (!parseCount(f[4 + std::size_t(a)], e.dims[std::size_t(a)])) return false;
  e.name = f[1];
  e.file = f[2];
  e.format = f[3];
  e.dtype = f[7];
  e.note = f[8];
  entry = std::move(e);
  return true;
}

}  // namespace

std::variant<std::vector<proto::CatalogEntry>, proto::ProtocolError> listDatasets(
    const std::string& nodePath, const std::string& dataDir, double timeoutSeconds,
    const std::function<void(const std::string&)>& note) {
  const std::string command = nodePath + " --catalog " + dataDir;
  const auto failed = [&](ErrorCode code, const std::string& why) {
    return proto::ProtocolError{code, "cannot list the catalog: " + command + ": " + why};
  };
  JobProcess program;
  std::string error;
  if (!program.start({nodePath, "--catalog", dataDir}, {}, SIGKILL, error)) return failed(ErrorCode::kIo, error);

  // Step: read its lines until its output ends, within the time limit.
  const double deadline = monotonicSeconds() + timeoutSeconds;
  std::vector<proto::CatalogEntry> entries;
  std::string lastNote, malformed;
  while (program.outputFd() >= 0 || !program.reap()) {
    const double left = deadline - monotonicSeconds();
    if (left <= 0) {
      program.stop();
      char limit[32];
      std::snprintf(limit, sizeof limit, "%g", timeoutSeconds);
      return failed(ErrorCode::kTimeout, std::string("did not finish in ") + limit + " s");
    }
    if (program.outputFd() < 0) {  // output closed: waiting for the exit
      ::usleep(5000);
      continue;
    }
    pollfd fd{program.outputFd(), POLLIN, 0};
    ::poll(&fd, 1, std::max(1, int(left * 1000)));
    for (std::string& line : program.readLines()) {
      proto::CatalogEntry entry;
      if (parseEntry(line, entry)) {
        entries.push_back(std::move(entry));
      } else if (!line.empty() && std::isdigit(static_cast<unsigned char>(line[0]))) {
        malformed = line;
      } else if (!line.empty()) {
        note(line);
        lastNote = line;
      }
    }
  }

  // Step: only a clean exit is a catalog.
  if (program.exitText() != "exited with status 0")
    return failed(ErrorCode::kIo, program.exitText() + (lastNote.empty() ? "" : ": " + lastNote));
  if (!malformed.empty())
    return failed(ErrorCode::kIo, "malformed line '" + printable({reinterpret_cast<const std::uint8_t*>(malformed.data()),
                                                                  malformed.size()}, 80) + "'");
  if (auto tooLarge = checkCatalogSize(entries)) return *tooLarge;
  return entries;
}

std::optional<proto::ProtocolError> checkCatalogSize(const std::vector<proto::CatalogEntry>& entries) {
  // The reply as it would go out, measured by the codec, against the
  // limit the protocol's message table gives CatalogReply: what a client
  // would refuse is never sent (issue 15, finding 15).
  proto::CatalogReply reply{entries};
  const std::uint32_t limit = proto::payloadLimit(proto::messageInfo(reply), proto::Limits{});
  const std::size_t payload = proto::encode(reply, 0).size() - proto::kHeaderBytes;
  if (payload <= limit) return std::nullopt;
  return proto::ProtocolError{ErrorCode::kLimitExceeded,
                              "the catalog of " + std::to_string(entries.size()) + " datasets is " + std::to_string(payload) +
                                  " bytes, over the protocol's limit of " + std::to_string(limit) +
                                  " bytes for a catalog reply; serve fewer datasets from the data directory (a time "
                                  "series counts once) or shorter names"};
}

std::variant<std::string, proto::ProtocolError> resolveDataset(const std::string& dataDir, const std::string& name) {
  if (name.empty() || name[0] == '/' || name.find('\0') != std::string::npos)
    return proto::ProtocolError{ErrorCode::kBadArgument, "dataset names are relative to the data directory"};
  for (const auto& part : fs::path(name))
    if (part == "..") return proto::ProtocolError{ErrorCode::kBadArgument, "dataset name '" + name + "' contains '..'"};
  const std::string root = realPath(dataDir);
  const std::string real = realPath(root + "/" + name);
  std::error_code ec;
  if (root.empty() || !inside(root, real) || !fs::is_regular_file(real, ec))
    return proto::ProtocolError{ErrorCode::kDatasetNotFound, "no dataset '" + name + "' in the catalog"};
  return real;
}

}  // namespace pvr::daemon
