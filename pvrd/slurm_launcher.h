// The slurm launcher: salloc asks Slurm for the ranks and runs mpirun
// inside the allocation (Debian's Open MPI reads the allocation and starts
// its daemons with srun). salloc's stderr tells the queue state
// (salloc_output.h); the allocation is given back when the session ends.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "launcher.h"

namespace pvr::daemon {

std::unique_ptr<Launcher> makeSlurmLauncher(const DaemonOptions& options);

// salloc --ntasks=N [--partition=P] [--time=T] [--account=A] --job-name=NAME
//        --kill-command=TERM MPIRUN-COMMAND...
// Each salloc option is one word, so the first word not starting with '-'
// begins the command (a fake salloc in the tests relies on it).
std::vector<std::string> sallocCommand(const JobSpec& spec, const DaemonOptions& options);

}  // namespace pvr::daemon
