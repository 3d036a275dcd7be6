// One launched command (mpirun, salloc, scancel): started in its own process
// group with pvrd's whole environment plus a few variables, its stdout and
// stderr read back through one pipe as lines, and stopped with every
// process descended from it.
#pragma once

#include <sys/types.h>

#include <string>
#include <utility>
#include <vector>

namespace pvr::daemon {

class JobProcess {
 public:
  using Environment = std::vector<std::pair<std::string, std::string>>;

  JobProcess() = default;
  JobProcess(const JobProcess&) = delete;
  JobProcess& operator=(const JobProcess&) = delete;
  ~JobProcess() {
    stop();
    closeOutput();
  }

  // Forks and execs argv[0] (PATH searched) with stdin from /dev/null,
  // `environment` set on top of this process's environment, in a new
  // process group, receiving `deathSignal` when the handler dies. False,
  // with error text, when it cannot fork; an exec failure shows as output
  // and exit status 127.
  bool start(const std::vector<std::string>& argv, const Environment& environment, int deathSignal,
             std::string& error);

  pid_t pid() const { return pid_; }
  // The read end of the output pipe; -1 before start and after its end.
  int outputFd() const { return output_; }
  // The complete lines that arrived since the last call (without '\n'); at
  // the end of the output, also the unterminated last one.
  std::vector<std::string> readLines();
  // The last few kilobytes of output.
  const std::string& tail() const { return tail_; }

  // True once the process exited (it is reaped here).
  bool reap();
  // "exited with status 1", "killed by signal 9".
  std::string exitText() const;

  // SIGTERM to the process group and to every descendant (children that
  // made their own groups included), SIGKILL after `graceSeconds`, reaped.
  // What it printed meanwhile stays readable. Idempotent.
  void stop(double graceSeconds = 1.0);
  void closeOutput();
  // Exited by itself with a status (not killed by a signal).
  bool exitedNormally() const;

 private:
  pid_t pid_ = -1;
  int output_ = -1;
  bool exited_ = false;
  int status_ = 0;
  std::string partial_;  // a line begun, not yet ended
  std::string tail_;
};

}  // namespace pvr::daemon
