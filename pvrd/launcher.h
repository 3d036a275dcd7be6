// How a session's job starts and ends. The session handler talks to a
// Launcher and does not know which one runs: mpirun on --hostfile's hosts
// (mpirun_launcher.h) or mpirun inside a Slurm allocation (slurm_launcher.h).
// A new launcher is one file plus one line in the table of launcher.cpp.
#pragma once

#include <signal.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "job_process.h"
#include "options.h"

namespace pvr::daemon {

// One session's job.
struct JobSpec {
  std::uint32_t ranks = 0;
  std::string nodePath;  // the pvr-node executable
  std::string connect;   // "ADDR:PORT" the master rank connects back to
  std::string dataDir;
  std::string secret;    // travels as PVR_JOB_SECRET in the environment, never in argv
  std::string account;   // batch account, isValidAccount; "": the site's default
  std::string name;      // "pvr-<pvrd pid>-<session>": the batch job's name
  std::uint64_t session = 0;  // for log records
};

// What a launcher read in its job's output.
struct LaunchEvent {
  enum class Kind {
    kQueued,   // waiting for a batch allocation (batchJob, reason)
    kGranted,  // the ranks have their hosts: the master connects soon
    kLost,     // the job's resources are gone (a revoked allocation): end the session
  };
  Kind kind = Kind::kGranted;
  std::string batchJob;  // the batch system's job id; "" when not known
  std::string reason;    // in the batch system's words
  bool operator==(const LaunchEvent&) const = default;
};

class Launcher {
 public:
  virtual ~Launcher() = default;
  Launcher(const Launcher&) = delete;
  Launcher& operator=(const Launcher&) = delete;

  // The program it runs ("mpirun", "salloc"), for log records.
  virtual std::string_view program() const = 0;
  // Starts the job in its own process group with PVR_JOB_SECRET (and, as
  // root, Open MPI's run-as-root permission) added to pvrd's environment.
  // False, with error text, when it cannot.
  bool start(const JobSpec& spec, std::string& error);
  pid_t pid() const { return process_.pid(); }
  // The job's output (stdout and stderr); -1 once it ended.
  int outputFd() const { return process_.outputFd(); }
  // Reads the output that arrived; returns what it announced.
  std::vector<LaunchEvent> readOutput();
  // True once the launched program exited.
  bool exited() { return process_.reap(); }
  // "mpirun exited with status 1".
  std::string exitText() const { return std::string(program()) + " " + process_.exitText(); }
  // The client's error text for a job that ended because of `why`, naming
  // the failed rank or the lost allocation when the output says which.
  virtual std::string endText(const std::string& why) const = 0;
  // Stops the job, every process of it, and releases what it holds.
  // Idempotent.
  void stop();

 protected:
  explicit Launcher(const DaemonOptions& options) : options_(options) {}
  // argv of the job.
  virtual std::vector<std::string> command(const JobSpec& spec) const = 0;
  // What the launched program receives when the handler dies: SIGKILL for
  // mpirun; a batch client is given the chance to release its allocation.
  virtual int deathSignal() const { return SIGKILL; }
  // One line of output; an event when it announces one.
  virtual std::optional<LaunchEvent> onLine(const std::string& line) {
    (void)line;
    return std::nullopt;
  }
  // After the job's processes are gone: give back what outlives them.
  virtual void release() {}

  const DaemonOptions& options_;
  JobProcess process_;
  std::uint64_t session_ = 0;
};

// The launcher --launcher names (options checked it is one).
std::unique_ptr<Launcher> makeLauncher(const DaemonOptions& options);
bool isLauncherName(std::string_view name);
// "mpirun, slurm": for messages.
std::string launcherNames();

// True for a batch account pvrd passes on: only A-Z a-z 0-9 _ . - (empty:
// the site's default).
bool isValidAccount(std::string_view account);

}  // namespace pvr::daemon
