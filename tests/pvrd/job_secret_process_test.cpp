// The session's secret with real processes: connect-backs without it are
// refused and logged while the session waits for the master that has it;
// the secret reaches the job in its environment and in no argv.
#include <catch2/catch.hpp>

#include <regex>

#include "daemon_harness.h"
#include "fake_master.h"

using namespace pvr::daemon::testing;

namespace {

std::vector<std::string> linesContaining(const std::string& text, const std::string& what) {
  std::vector<std::string> found;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);)
    if (line.find(what) != std::string::npos) found.push_back(line);
  return found;
}

// The job's secret as its launched process received it, checked to be 64
// lowercase hex digits and absent from the argv of every job process.
void checkSecretOnlyInEnvironment(const fs::path& dataDir, pid_t launched) {
  const std::string secret = startEnvironmentValue(launched, "PVR_JOB_SECRET");
  CHECK(std::regex_match(secret, std::regex("[0-9a-f]{64}")));
  const auto processes = jobProcesses(dataDir);
  REQUIRE_FALSE(processes.empty());
  for (pid_t p : processes) {
    const auto argv = procEntries(p, "cmdline");
    INFO("job process " << p << ": " << (argv.empty() ? "(gone)" : argv.front()));
    for (const std::string& a : argv) CHECK(a.find(secret) == std::string::npos);
  }
}

}  // namespace

TEST_CASE("connect-backs keyed by a wrong secret, without the channel, with a wrong JobHello, another frame or silence are refused and logged, and the master with the secret opens the session") {
  namespace fake = pvr::daemon::testing;
  const fs::path dir = makeDataDir("secret");
  const std::string trials = std::string(fake::kTrialSilent) + "," + std::string(fake::kTrialWrongSecret) + "," +
                             std::string(fake::kTrialNoSecret) + "," + std::string(fake::kTrialWrongJobHello) + "," +
                             std::string(fake::kTrialOtherFrame);
  Daemon d(dir, {"--mpirun", FAKE_MASTER_PATH}, {{fake::kTrialsVariable, trials}}, logPath("secret"));
  Client c(d.port);
  c.hello();
  c.openSession();
  c.send(proto::SetScene{"", std::string(fake::kScriptGood)});
  c.expect<proto::Ok>();
  c.send(proto::RenderFrame{});
  CHECK(c.expect<proto::ImageFrame>() == fake::fakeGoodFrame());

  // The launched process is the fake master itself: its environment holds
  // the secret (and the trial list, so pvrd passed its environment on).
  const auto launched = jobProcesses(dir);
  REQUIRE(launched.size() == 1);
  CHECK(startEnvironmentValue(launched[0], fake::kTrialsVariable) == trials);
  checkSecretOnlyInEnvironment(dir, launched[0]);
  // mpirun is told to hand the variable to every rank.
  const auto argv = procEntries(launched[0], "cmdline");
  const std::vector<std::string> export_{"-x", "PVR_JOB_SECRET"};
  CHECK(std::search(argv.begin(), argv.end(), export_.begin(), export_.end()) != argv.end());

  // One log line per refused connection, each naming its peer and reason.
  const std::string log = d.log();
  const auto refusals = linesContaining(log, "refused a connect-back from 127.0.0.1:");
  CHECK(refusals.size() == 5);
  // Keyed by another secret, or no channel at all: the handshake fails,
  // before any frame.
  CHECK(linesContaining(log, ": secure channel: the handshake failed (").size() == 2);
  CHECK(linesContaining(log, ": JobHello with a wrong secret; first bytes '").size() == 1);
  CHECK(linesContaining(log, ": its first frame is SessionReady, not JobHello; first bytes '").size() == 1);
  CHECK(linesContaining(log, ": the master connected first; first bytes ''").size() == 1);
  // The wrong secret's control bytes are masked, never written raw.
  CHECK(log.find("\\x01wrong\\x7f") != std::string::npos);
  CHECK(log.find('\x01') == std::string::npos);
  CHECK(log.find(startEnvironmentValue(launched[0], "PVR_JOB_SECRET")) == std::string::npos);

  c.send(proto::Close{"done"});
  CHECK(c.expect<proto::Close>().reason == "bye");
  CHECK(secondsUntilJobGone(dir, 2) >= 0);
}

TEST_CASE("the real job gets its secret and pvrd's environment, and no process of it shows the secret in its argv") {
  const fs::path dir = makeDataDir("realsecret");
  Daemon d(dir, {}, {{"OMPI_MCA_btl", "self,tcp"}});
  Client c(d.port);
  c.hello();
  c.openSession();
  c.renderAndCheck();
  pid_t mpirun = -1;
  for (pid_t p : jobProcesses(dir)) {
    const auto argv = procEntries(p, "cmdline");
    if (!argv.empty() && argv.front().find("mpirun") != std::string::npos) mpirun = p;
  }
  REQUIRE(mpirun > 0);
  CHECK(startEnvironmentValue(mpirun, "OMPI_MCA_btl") == "self,tcp");
  checkSecretOnlyInEnvironment(dir, mpirun);
  c.send(proto::Close{"done"});
  CHECK(c.expect<proto::Close>().reason == "bye");
}

TEST_CASE("a client that sends JobHello gets UNEXPECTED_MESSAGE and is served on") {
  Daemon d(makeDataDir("clientjobhello"));
  Client c(d.port);
  c.hello();
  c.send(proto::JobHello{"0123"});
  const auto e = c.expectError(5);
  CHECK(e.code == proto::ErrorCode::kUnexpectedMessage);
  CHECK(e.text == "JobHello is the rendering job's message, not a client's");
  c.send(proto::CatalogRequest{});
  CHECK(c.expect<proto::CatalogReply>().datasets.size() == 1);
}

TEST_CASE("an account with characters outside A-Z a-z 0-9 _ . - is refused before any job starts") {
  const fs::path dir = makeDataDir("badaccount");
  Daemon d(dir);
  Client c(d.port);
  c.hello();
  for (const std::string account : {"a b", "x;rm -rf /", "--partition=big", "acc\n"}) {
    INFO("account '" << account << "'");
    const auto id = c.send(proto::SessionOpen{2, {}, account});
    const auto reply = c.next(5);
    REQUIRE(reply);
    CHECK(reply->info == proto::FrameInfo{id, proto::kFlagFinal});
    REQUIRE(std::holds_alternative<proto::ErrorMessage>(reply->message));
    CHECK(std::get<proto::ErrorMessage>(reply->message).code == proto::ErrorCode::kBadArgument);
    CHECK(jobProcesses(dir).empty());
  }
  c.openSession();
}
