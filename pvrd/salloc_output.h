// What salloc says on stderr about its allocation, as Slurm 22.05 (Debian
// 12) words it, e.g.
//   salloc: Pending job allocation 12
//   salloc: job 12 queued and waiting for resources
//   salloc: job 12 has been allocated resources
//   salloc: Granted job allocation 12
//   salloc: Job allocation 12 has been revoked.
//   salloc: error: Job submit/allocate failed: Invalid account or account/partition combination specified
//   salloc: Relinquishing job allocation 12
// Lines of other programs sharing the pipe (mpirun, the ranks) are not
// salloc's and are left alone.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "launcher.h"

namespace pvr::daemon {

struct SallocLine {
  enum class Kind {
    kQueued,    // the request waits in the queue
    kGranted,   // the allocation exists
    kRevoked,   // the allocation (or the pending request) was cancelled or ran out of time
    kReleased,  // salloc gives the allocation back
    kError,     // "error:" or "fatal:" about anything else
  };
  Kind kind = Kind::kError;
  std::string job;     // the job id the line names; "" when it names none
  std::string reason;  // salloc's words: "queued and waiting for resources", the error text
  bool operator==(const SallocLine&) const = default;
};

// The meaning of one line of salloc's stderr; nullopt for lines that are
// not salloc's or say nothing about the allocation.
std::optional<SallocLine> parseSallocLine(std::string_view line);

// Follows one salloc through its lines: the job id, whether the allocation
// was granted, lost or released, and the error that explains a failure.
class SallocMonitor {
 public:
  // The event a line announces to the session: kQueued while the request
  // waits, kGranted, kLost when the allocation is revoked.
  std::optional<LaunchEvent> onLine(std::string_view line);

  const std::string& job() const { return job_; }
  bool granted() const { return granted_; }
  bool released() const { return released_; }
  // The client's text for a job that ended because of `why` (salloc's exit,
  // the master's loss): "slurm: allocation 12 failed: <salloc's reason>"
  // when the allocation failed or never came; nullopt when it was in place
  // and the ranks themselves ended.
  std::optional<std::string> failureText(const std::string& why) const;

 private:
  std::string job_;
  bool granted_ = false;
  bool released_ = false;
  std::string revoked_;    // the line that revoked the allocation
  std::string lastError_;  // the last error line
};

}  // namespace pvr::daemon
