// salloc's stderr as the slurm launcher reads it. The lines are salloc
// 22.05's (Debian 12) messages: the pending, queued, granted, revoked and
// released lines filled in from the format strings of /usr/bin/salloc and
// libslurmfull.so, the "fatal" lines as salloc printed them on a host
// without a Slurm configuration.
#include <catch2/catch.hpp>

#include "salloc_output.h"

using namespace pvr::daemon;
using K = SallocLine::Kind;
using E = LaunchEvent::Kind;

TEST_CASE("salloc lines: queue, grant, revocation, release and errors are recognised with their job id") {
  CHECK(parseSallocLine("salloc: Pending job allocation 12") == SallocLine{K::kQueued, "12", "pending"});
  CHECK(parseSallocLine("salloc: job 12 queued and waiting for resources") ==
        SallocLine{K::kQueued, "12", "queued and waiting for resources"});
  CHECK(parseSallocLine("salloc: job 12 has been allocated resources") ==
        SallocLine{K::kGranted, "12", "allocated resources"});
  CHECK(parseSallocLine("salloc: Granted job allocation 12\r") == SallocLine{K::kGranted, "12", "granted"});
  CHECK(parseSallocLine("salloc: Job allocation 12 has been revoked.") ==
        SallocLine{K::kRevoked, "12", "Job allocation 12 has been revoked."});
  CHECK(parseSallocLine("salloc: error: Job allocation 12 has been revoked") ==
        SallocLine{K::kRevoked, "12", "Job allocation 12 has been revoked"});
  CHECK(parseSallocLine("salloc: Job 12 has exceeded its time limit and its allocation has been revoked.") ==
        SallocLine{K::kRevoked, "12", "Job 12 has exceeded its time limit and its allocation has been revoked."});
  CHECK(parseSallocLine("salloc: error: Allocation was revoked for job 12 before command could be run") ==
        SallocLine{K::kRevoked, "12", "Allocation was revoked for job 12 before command could be run"});
  CHECK(parseSallocLine("salloc: Job has been cancelled") == SallocLine{K::kRevoked, "", "Job has been cancelled"});
  CHECK(parseSallocLine("salloc: Relinquishing job allocation 12") == SallocLine{K::kReleased, "12", "released"});
  CHECK(parseSallocLine("salloc: error: Job submit/allocate failed: Invalid account or account/partition combination specified") ==
        SallocLine{K::kError, "", "Job submit/allocate failed: Invalid account or account/partition combination specified"});
  CHECK(parseSallocLine("salloc: fatal: Could not establish a configuration source") ==
        SallocLine{K::kError, "", "Could not establish a configuration source"});
}

TEST_CASE("salloc lines: other salloc news and other programs' lines mean nothing") {
  CHECK_FALSE(parseSallocLine("salloc: Waiting for resource configuration"));
  CHECK_FALSE(parseSallocLine("salloc: Nodes h[1-2] are ready for job"));
  CHECK_FALSE(parseSallocLine("salloc: Job aborted due to signal"));
  CHECK_FALSE(parseSallocLine("mpirun noticed that process rank 1 with PID 4242 on node h1 exited on signal 9"));
  CHECK_FALSE(parseSallocLine("rank 0: salloc: Granted job allocation 12"));
  CHECK_FALSE(parseSallocLine(""));
}

TEST_CASE("salloc monitor: a queued request that is granted reports progress, then the grant") {
  SallocMonitor m;
  CHECK(m.onLine("salloc: Pending job allocation 31") == LaunchEvent{E::kQueued, "31", "pending"});
  CHECK(m.onLine("salloc: job 31 queued and waiting for resources") ==
        LaunchEvent{E::kQueued, "31", "queued and waiting for resources"});
  CHECK(m.onLine("salloc: job 31 has been allocated resources") == LaunchEvent{E::kGranted, "31", "allocated resources"});
  CHECK(m.onLine("salloc: Granted job allocation 31") == LaunchEvent{E::kGranted, "31", "granted"});
  CHECK_FALSE(m.onLine("salloc: Nodes h1 are ready for job"));
  CHECK(m.job() == "31");
  CHECK(m.granted());
  // The allocation was in place: a job that ends is the ranks' business.
  CHECK_FALSE(m.failureText("mpirun exited with status 1"));
  CHECK_FALSE(m.released());
  CHECK_FALSE(m.onLine("salloc: Relinquishing job allocation 31"));
  CHECK(m.released());
}

TEST_CASE("salloc monitor: a revoked allocation is lost, and the failure names the job and salloc's words") {
  SallocMonitor m;
  m.onLine("salloc: Granted job allocation 8");
  CHECK(m.onLine("salloc: Job allocation 8 has been revoked.") ==
        LaunchEvent{E::kLost, "8", "Job allocation 8 has been revoked."});
  CHECK(m.failureText("the master rank's connection closed") ==
        "slurm: allocation 8 failed: Job allocation 8 has been revoked.");
}

TEST_CASE("salloc monitor: a request that never got its allocation fails with salloc's last error") {
  SallocMonitor refused;
  CHECK_FALSE(refused.onLine("salloc: error: Job submit/allocate failed: Invalid partition name specified"));
  CHECK(refused.failureText("salloc exited with status 1") ==
        "slurm: allocation failed: Job submit/allocate failed: Invalid partition name specified");

  SallocMonitor cancelled;
  cancelled.onLine("salloc: Pending job allocation 5");
  CHECK(cancelled.onLine("salloc: Job has been cancelled") == LaunchEvent{E::kLost, "5", "Job has been cancelled"});
  cancelled.onLine("salloc: error: Job submit/allocate failed: Job/step already completing or completed");
  CHECK(cancelled.failureText("salloc exited with status 1") == "slurm: allocation 5 failed: Job has been cancelled");

  SallocMonitor silent;
  CHECK(silent.failureText("salloc exited with status 127") == "slurm: allocation failed: salloc exited with status 127");
}
