// The command lines the launchers build, the launcher table and the
// account rule.
#include <catch2/catch.hpp>

#include "launcher.h"
#include "mpirun_launcher.h"
#include "slurm_launcher.h"

using namespace pvr::daemon;
using Args = std::vector<std::string>;

namespace {

JobSpec spec(std::string account = "") {
  return JobSpec{3, "/opt/pvr/pvr-node", "10.213.7.10:40001", "/data", std::string(64, 'a'), account, "pvr-100-7", 7};
}

DaemonOptions options(const std::string& launcher) {
  DaemonOptions o;
  o.launcher = launcher;
  o.dataDir = "/data";
  return o;
}

}  // namespace

TEST_CASE("mpirun command: ranks, hostfile, the secret exported by name, the connect-back address") {
  DaemonOptions o = options("mpirun");
  o.hostfile = "/etc/pvr/hosts";
  CHECK(mpirunCommand(spec(), o, true) ==
        Args{"mpirun", "--oversubscribe", "--bind-to", "none", "-np", "3", "--hostfile", "/etc/pvr/hosts", "-x",
             "PVR_JOB_SECRET", "/opt/pvr/pvr-node", "--server", "--connect", "10.213.7.10:40001", "--data-dir",
             "/data", "--stall-timeout", "30"});
  CHECK(mpirunCommand(spec(), o, false) ==
        Args{"mpirun", "--oversubscribe", "--bind-to", "none", "-np", "3", "-x", "PVR_JOB_SECRET",
             "/opt/pvr/pvr-node", "--server", "--connect", "10.213.7.10:40001", "--data-dir", "/data",
             "--stall-timeout", "30"});
}

TEST_CASE("salloc command: one word per option, then mpirun inside the allocation, and the secret never in argv") {
  DaemonOptions o = options("slurm");
  CHECK(sallocCommand(spec(), o) ==
        Args{"salloc", "--ntasks=3", "--job-name=pvr-100-7", "--kill-command=TERM", "mpirun", "--oversubscribe",
             "--bind-to", "none", "-np", "3", "-x", "PVR_JOB_SECRET", "/opt/pvr/pvr-node", "--server", "--connect",
             "10.213.7.10:40001", "--data-dir", "/data", "--stall-timeout", "30"});
  o.partition = "vis";
  o.time = "1:00:00";
  o.salloc = "/usr/local/bin/salloc";
  const Args full = sallocCommand(spec("proj-7"), o);
  CHECK(Args(full.begin(), full.begin() + 7) == Args{"/usr/local/bin/salloc", "--ntasks=3", "--partition=vis",
                                                      "--time=1:00:00", "--account=proj-7", "--job-name=pvr-100-7",
                                                      "--kill-command=TERM"});
  CHECK(full[7] == "mpirun");
  for (const std::string& word : full) CHECK(word.find(spec().secret) == std::string::npos);
}

TEST_CASE("the launcher table makes each launcher by name") {
  CHECK(launcherNames() == "mpirun, slurm");
  CHECK(isLauncherName("slurm"));
  CHECK_FALSE(isLauncherName("pbs"));
  CHECK(makeLauncher(options("mpirun"))->program() == "mpirun");
  CHECK(makeLauncher(options("slurm"))->program() == "salloc");
}

TEST_CASE("accounts hold only A-Z a-z 0-9 _ . -") {
  CHECK(isValidAccount(""));
  CHECK(isValidAccount("proj_1.a-B"));
  for (const char* bad : {"a b", "a;b", "a=b", "a/b", "a\nb", "ä", "$HOME"}) CHECK_FALSE(isValidAccount(bad));
}
