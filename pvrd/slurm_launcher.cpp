#include "slurm_launcher.h"

#include <unistd.h>

#include "mpirun_launcher.h"
#include "salloc_output.h"
#include "sys.h"

namespace pvr::daemon {
namespace {

// How long scancel may take to reach the controller: a stopping pvrd
// gives each handler 5 s in all (pvrd_main.cpp).
constexpr double kScancelSeconds = 3;

class SlurmLauncher final : public Launcher {
 public:
  explicit SlurmLauncher(const DaemonOptions& options) : Launcher(options) {}
  std::string_view program() const override { return "salloc"; }

  std::string endText(const std::string& why) const override {
    // When salloc said nothing about the allocation (it could not even
    // start), its last line of output is the best reason there is.
    std::string lastLine = process_.tail();
    while (!lastLine.empty() && lastLine.back() == '\n') lastLine.pop_back();
    lastLine.erase(0, lastLine.rfind('\n') + 1);
    if (auto failed = monitor_.failureText(lastLine.empty() ? why : why + ": " + lastLine)) return *failed;
    return mpirunEndText(why, process_.tail());
  }

 private:
  std::vector<std::string> command(const JobSpec& spec) const override { return sallocCommand(spec, options_); }

  // SIGTERM: salloc passes it to mpirun, waits for it and relinquishes the
  // allocation; SIGKILL would leave the allocation to the time limit.
  int deathSignal() const override { return SIGTERM; }

  std::optional<LaunchEvent> onLine(const std::string& line) override { return monitor_.onLine(line); }

  // salloc gives the allocation back when it ends in order; when it was
  // killed, or never said so, scancel makes sure.
  void release() override {
    if (monitor_.job().empty() || (monitor_.released() && process_.exitedNormally())) return;
    JobProcess scancel;
    std::string error;
    if (!scancel.start({options_.scancel, monitor_.job()}, {}, SIGKILL, error)) {
      logEvent(session_, "cannot run scancel " + monitor_.job() + ": " + error);
      return;
    }
    const double t0 = monotonicSeconds();
    while (!scancel.reap() && monotonicSeconds() - t0 < kScancelSeconds) ::usleep(10000);
    scancel.stop();
    std::string said;
    for (const std::string& line : scancel.readLines()) said += " " + line;
    logEvent(session_, "scancel " + monitor_.job() + " " + scancel.exitText() + (said.empty() ? "" : ":" + said));
  }

  SallocMonitor monitor_;
};

}  // namespace

std::unique_ptr<Launcher> makeSlurmLauncher(const DaemonOptions& options) {
  return std::make_unique<SlurmLauncher>(options);
}

std::vector<std::string> sallocCommand(const JobSpec& spec, const DaemonOptions& options) {
  std::vector<std::string> args{options.salloc, "--ntasks=" + std::to_string(spec.ranks)};
  if (!options.partition.empty()) args.push_back("--partition=" + options.partition);
  if (!options.time.empty()) args.push_back("--time=" + options.time);
  if (!spec.account.empty()) args.push_back("--account=" + spec.account);
  // --kill-command: when Slurm revokes the allocation, mpirun hears of it
  // at once instead of from its vanished daemons.
  args.insert(args.end(), {"--job-name=" + spec.name, "--kill-command=TERM"});
  const auto mpirun = mpirunCommand(spec, options, false);
  args.insert(args.end(), mpirun.begin(), mpirun.end());
  return args;
}

}  // namespace pvr::daemon
