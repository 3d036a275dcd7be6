// The slurm launcher with real processes and no Slurm: pvrd runs a fake
// salloc (fake_salloc.sh, which prints salloc 22.05's lines and then runs
// the fake master) and a fake scancel that notes the job ids it is given.
#include <catch2/catch.hpp>

#include <sstream>

#include "daemon_harness.h"
#include "fake_master.h"

using namespace pvr::daemon::testing;

namespace {

// A data directory and the files of one slurm test: the fake scancel's
// notes, the fake salloc's triggers, pvrd's log.
struct SlurmFiles {
  fs::path dataDir, scancelLog, grant, revoke, log;
  explicit SlurmFiles(const std::string& tag) : dataDir(makeDataDir(tag)) {
    const fs::path base = dataDir.parent_path() / (tag + "_" + std::to_string(::getpid()));
    fs::remove_all(base);
    fs::create_directories(base);
    scancelLog = base / "scancel.log";
    grant = base / "grant";
    revoke = base / "revoke";
    log = base / "pvrd.log";
  }
};

std::vector<std::string> slurmOptions() {
  return {"--launcher", "slurm", "--salloc", FAKE_SALLOC_PATH, "--scancel", FAKE_SCANCEL_PATH, "--mpirun",
          FAKE_MASTER_PATH, "--partition", "vis", "--time", "10"};
}

void touch(const fs::path& path) { std::ofstream(path) << "now\n"; }

// The next frame answers request `id` as queue progress: a non-final
// StatusReply saying queued, the batch job and salloc's reason.
void expectQueued(Client& c, std::uint32_t id, const std::string& job, const std::string& reason) {
  const auto d = c.next(10);
  REQUIRE(d);
  CHECK(d->info == proto::FrameInfo{id, 0});
  REQUIRE(std::holds_alternative<proto::StatusReply>(d->message));
  CHECK(std::get<proto::StatusReply>(d->message).entries ==
        std::vector<proto::KeyValue>{{"state", "queued"}, {"batch_job", job}, {"reason", reason}});
}

// The processes of `pids` whose parent is not in `pids`.
std::vector<pid_t> outermost(const std::vector<pid_t>& pids) {
  std::vector<pid_t> out;
  for (pid_t p : pids) {
    const auto stat = pvr::testing::procStat(p);
    const pid_t parent = stat ? stat->parent : 0;
    if (std::find(pids.begin(), pids.end(), parent) == pids.end()) out.push_back(p);
  }
  return out;
}

}  // namespace

TEST_CASE("slurm: the queue's progress reaches the client, status says queued, then the session works and the allocation is cancelled at its end") {
  SlurmFiles f("slurmqueued");
  Daemon d(f.dataDir, slurmOptions(), {{"FAKE_SALLOC_GRANT_WHEN", f.grant}, {"FAKE_SCANCEL_LOG", f.scancelLog}}, f.log);
  Client c(d.port);
  c.hello();
  const auto open = c.send(proto::SessionOpen{2, {}, "proj_1.a-b"});
  expectQueued(c, open, "4242", "pending");
  expectQueued(c, open, "4242", "queued and waiting for resources");
  const auto status = c.send(proto::StatusRequest{});
  const auto reply = c.next(10);
  REQUIRE(reply);
  CHECK(reply->info == proto::FrameInfo{status, proto::kFlagFinal});
  REQUIRE(std::holds_alternative<proto::StatusReply>(reply->message));
  CHECK(std::get<proto::StatusReply>(reply->message).entries.front() == proto::KeyValue{"state", "queued"});

  // salloc got the partition, time, account and job name as one word each.
  // (The fake salloc's polling forks a shell child that shows the same
  // command line until it execs sleep: keep only the process whose parent
  // is not itself one of the job's.)
  const auto salloc = outermost(jobProcesses(f.dataDir));
  REQUIRE(salloc.size() == 1);
  const auto argv = procEntries(salloc[0], "cmdline");
  for (const std::string& word : std::vector<std::string>{"--ntasks=2", "--partition=vis", "--time=10", "--account=proj_1.a-b",
                                 "--job-name=pvr-" + std::to_string(d.pid) + "-1"})
    CHECK(std::find(argv.begin(), argv.end(), word) != argv.end());

  touch(f.grant);
  const auto ready = c.next(30);
  REQUIRE(ready);
  CHECK(ready->info == proto::FrameInfo{open, proto::kFlagFinal});
  REQUIRE(std::holds_alternative<proto::SessionReady>(ready->message));
  c.send(proto::SetScene{"", std::string(kScriptGood)});
  c.expect<proto::Ok>();
  c.send(proto::RenderFrame{});
  CHECK(c.expect<proto::ImageFrame>() == fakeGoodFrame());
  c.send(proto::Close{"done"});
  CHECK(c.expect<proto::Close>().reason == "bye");
  CHECK(secondsUntilJobGone(f.dataDir, 3) >= 0);
  CHECK(fileComesToHold(f.scancelLog, "4242\n", 10));
}

TEST_CASE("slurm: a cancelled pending allocation answers SessionOpen with RANK_FAILED naming the job, and pvrd serves on") {
  SlurmFiles f("slurmcancelled");
  Daemon d(f.dataDir, slurmOptions(),
           {{"FAKE_SALLOC_OUTCOME", "cancelled"}, {"FAKE_SALLOC_JOB", "77"}, {"FAKE_SCANCEL_LOG", f.scancelLog}}, f.log);
  {
    Client c(d.port);
    c.hello();
    const auto open = c.send(proto::SessionOpen{2, {}, ""});
    expectQueued(c, open, "77", "pending");
    expectQueued(c, open, "77", "queued and waiting for resources");
    const auto e = c.next(30);
    REQUIRE(e);
    CHECK(e->info == proto::FrameInfo{open, proto::kFlagFinal});
    REQUIRE(std::holds_alternative<proto::ErrorMessage>(e->message));
    CHECK(std::get<proto::ErrorMessage>(e->message) ==
          proto::ErrorMessage{proto::ErrorCode::kRankFailed, "slurm: allocation 77 failed: Job has been cancelled"});
    CHECK(c.expect<proto::Close>(5).reason.size() > 0);
    CHECK(secondsUntilJobGone(f.dataDir, 3) >= 0);
  }
  Client again(d.port);
  again.hello();
  again.send(proto::CatalogRequest{});
  CHECK(again.expect<proto::CatalogReply>().datasets.size() == 1);
}

TEST_CASE("slurm: an allocation revoked while the session runs ends it with RANK_FAILED naming the allocation") {
  SlurmFiles f("slurmrevoked");
  Daemon d(f.dataDir, slurmOptions(),
           {{"FAKE_SALLOC_OUTCOME", "revoked"}, {"FAKE_SALLOC_REVOKE_WHEN", f.revoke}, {"FAKE_SCANCEL_LOG", f.scancelLog}},
           f.log);
  Client c(d.port);
  c.hello();
  c.send(proto::SessionOpen{2, {}, ""});
  for (int i = 0; i < 2; ++i) c.expect<proto::StatusReply>(10);
  c.expect<proto::SessionReady>(30);
  touch(f.revoke);
  const auto e = c.expectError(10);
  CHECK(e.code == proto::ErrorCode::kRankFailed);
  CHECK(e.text == "slurm: allocation 4242 failed: Job allocation 4242 has been revoked.");
  CHECK(c.expect<proto::Close>(5).reason.size() > 0);
  CHECK(secondsUntilJobGone(f.dataDir, 3) >= 0);
}

TEST_CASE("slurm: the allocation is released when the client vanishes in the queue and when pvrd is stopped") {
  SlurmFiles f("slurmrelease");
  Daemon d(f.dataDir, slurmOptions(),
           {{"FAKE_SALLOC_GRANT_WHEN", f.grant}, {"FAKE_SALLOC_JOB", "91"}, {"FAKE_SCANCEL_LOG", f.scancelLog}}, f.log);
  SECTION("the client vanishes while the request waits in the queue") {
    Client c(d.port);
    c.hello();
    const auto open = c.send(proto::SessionOpen{2, {}, ""});
    expectQueued(c, open, "91", "pending");
    c.closeNow();
  }
  SECTION("pvrd gets SIGTERM while the session runs") {
    touch(f.grant);
    Client c(d.port);
    c.hello();
    c.send(proto::SessionOpen{2, {}, ""});
    for (int i = 0; i < 2; ++i) c.expect<proto::StatusReply>(10);
    c.expect<proto::SessionReady>(30);
    CHECK(d.stop() == 0);
  }
  CHECK(secondsUntilJobGone(f.dataDir, 3) >= 0);
  CHECK(fileComesToHold(f.scancelLog, "91\n", 10));
}

TEST_CASE("slurm: a salloc that cannot run answers SessionOpen with RANK_FAILED saying why") {
  SlurmFiles f("slurmmissing");
  std::vector<std::string> options = slurmOptions();
  options[3] = (f.dataDir / "no-salloc-here").string();
  Daemon d(f.dataDir, options, {{"FAKE_SCANCEL_LOG", f.scancelLog}}, f.log);
  Client c(d.port);
  c.hello();
  const auto open = c.send(proto::SessionOpen{2, {}, ""});
  const auto e = c.next(30);
  REQUIRE(e);
  CHECK(e->info == proto::FrameInfo{open, proto::kFlagFinal});
  REQUIRE(std::holds_alternative<proto::ErrorMessage>(e->message));
  const auto& error = std::get<proto::ErrorMessage>(e->message);
  CHECK(error.code == proto::ErrorCode::kRankFailed);
  CHECK(error.text == "slurm: allocation failed: salloc exited with status 127: exec: No such file or directory " +
                          options[3]);
  // No job id was ever given: there is nothing to cancel.
  CHECK_FALSE(fs::exists(f.scancelLog));
}
