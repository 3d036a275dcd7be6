// The mpirun launcher: Open MPI starts the ranks on this host or on the
// hosts of --hostfile (over ssh, or whatever OMPI_MCA_plm_* in pvrd's
// environment says).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "launcher.h"

namespace pvr::daemon {

std::unique_ptr<Launcher> makeMpirunLauncher(const DaemonOptions& options);

// mpirun --oversubscribe --bind-to none -np N [--hostfile F] -x PVR_JOB_SECRET
//        NODE --server --connect ADDR:PORT --data-dir DIR
// (--hostfile only when `withHostfile`: inside an allocation the batch
// system names the hosts).
std::vector<std::string> mpirunCommand(const JobSpec& spec, const DaemonOptions& options, bool withHostfile);

// The rank named in an mpirun error message ("... process rank 1 with PID ..."),
// or -1.
int rankFromMpirunOutput(const std::string& text);

// The host Open MPI says it lost contact with ("" when its output names none).
std::string lostHostFromMpirunOutput(const std::string& text);

// The client's text for an MPI job that ended because of `why`: the rank
// when mpirun's output names it, otherwise the end of that output.
std::string mpirunEndText(const std::string& why, const std::string& outputTail);

}  // namespace pvr::daemon
