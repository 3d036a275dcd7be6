#include "launcher.h"

#include <unistd.h>

#include "mpirun_launcher.h"
#include "pvr_protocol.h"
#include "slurm_launcher.h"

namespace pvr::daemon {
namespace {

struct LauncherEntry {
  std::string_view name;
  std::unique_ptr<Launcher> (*make)(const DaemonOptions&);
};

// Every launcher: --launcher NAME picks one.
constexpr LauncherEntry kLaunchers[] = {
    {"mpirun", makeMpirunLauncher},
    {"slurm", makeSlurmLauncher},
};

}  // namespace

bool Launcher::start(const JobSpec& spec, std::string& error) {
  session_ = spec.session;
  JobProcess::Environment environment{{proto::kJobSecretVariable, spec.secret}};
  if (::geteuid() == 0)
    environment.insert(environment.end(), {{"OMPI_ALLOW_RUN_AS_ROOT", "1"}, {"OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1"}});
  return process_.start(command(spec), environment, deathSignal(), error);
}

std::vector<LaunchEvent> Launcher::readOutput() {
  std::vector<LaunchEvent> events;
  for (const std::string& line : process_.readLines())
    if (auto e = onLine(line)) events.push_back(std::move(*e));
  return events;
}

void Launcher::stop() {
  if (process_.pid() <= 0) return;
  process_.stop();
  // What it printed while it went (a batch client's release) still counts.
  readOutput();
  process_.closeOutput();
  release();
}

std::unique_ptr<Launcher> makeLauncher(const DaemonOptions& options) {
  for (const auto& entry : kLaunchers)
    if (entry.name == options.launcher) return entry.make(options);
  return nullptr;
}

bool isLauncherName(std::string_view name) {
  for (const auto& entry : kLaunchers)
    if (entry.name == name) return true;
  return false;
}

std::string launcherNames() {
  std::string names;
  for (const auto& entry : kLaunchers) names += (names.empty() ? "" : ", ") + std::string(entry.name);
  return names;
}

bool isValidAccount(std::string_view account) {
  for (const char c : account) {
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' ||
                    c == '.' || c == '-';
    if (!ok) return false;
  }
  return true;
}

}  // namespace pvr::daemon
