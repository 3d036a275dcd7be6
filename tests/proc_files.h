// The tests' view of /proc: which processes run, their parents, command
// lines and environments.
//
// Read with open() and read(), never with iostreams: a process can end
// between the open and the read of its /proc file, and the read then fails
// with ESRCH, which libstdc++'s filebuf turns into an exception no stream
// flag stops ("basic_filebuf::underflow error reading the file: No such
// process"). A test scanning every process met that one time in a few
// dozen runs. Here a process that is gone reads as an empty file.
#pragma once

#include <fcntl.h>
#include <sys/types.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace pvr::testing {

// /proc/PID/NAME whole; "" when the process is gone or the file unreadable.
inline std::string procFile(pid_t pid, const char* name) {
  const std::string path = "/proc/" + std::to_string(pid) + "/" + name;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return {};
  std::string text;
  char buf[4096];
  for (ssize_t n; (n = ::read(fd, buf, sizeof buf)) > 0;) text.append(buf, std::size_t(n));
  ::close(fd);
  return text;
}

// The entries of a NUL-separated /proc file (cmdline, environ).
inline std::vector<std::string> procEntries(pid_t pid, const char* name) {
  std::vector<std::string> entries;
  std::istringstream in(procFile(pid, name));
  for (std::string entry; std::getline(in, entry, '\0');) entries.push_back(entry);
  return entries;
}

// The fields of /proc/PID/stat that tests ask about. The command name is in
// parentheses and may hold spaces and ')': the fields after it are read from
// the last ')'.
struct ProcStat {
  char state = '?';  // 'Z' for a zombie
  pid_t parent = 0;
};

inline std::optional<ProcStat> procStat(pid_t pid) {
  const std::string s = procFile(pid, "stat");
  const auto close = s.rfind(')');
  if (close == std::string::npos) return std::nullopt;
  ProcStat stat;
  if (!(std::istringstream(s.substr(close + 1)) >> stat.state >> stat.parent)) return std::nullopt;
  return stat;
}

// True while `pid` runs: not gone, not a zombie waiting to be reaped.
inline bool processRuns(pid_t pid) {
  const auto stat = procStat(pid);
  return stat && stat->state != 'Z';
}

// Every process id in /proc now.
inline std::vector<pid_t> allPids() {
  std::vector<pid_t> pids;
  std::error_code ignored;
  for (const auto& e : std::filesystem::directory_iterator("/proc", ignored))
    if (const pid_t pid = pid_t(std::atoi(e.path().filename().c_str())); pid > 0) pids.push_back(pid);
  return pids;
}

}  // namespace pvr::testing
