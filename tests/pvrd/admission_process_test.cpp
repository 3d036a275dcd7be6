// Admission and a handler that never blocks on one peer (issue 15,
// findings 6 and 7): strangers have their own small limit and a short
// handshake time and hold no session slot; a slot is taken at SessionOpen;
// a master that stopped reading neither wedges the handler nor keeps it
// from seeing its client leave; a master that stops altogether is seen.
#include <catch2/catch.hpp>

#include "daemon_harness.h"

using namespace pvr::daemon::testing;

namespace {

// The pvr-node process that is rank 0 of the job for `dataDir`.
pid_t masterRank(const fs::path& dataDir) {
  for (pid_t p : nodeProcesses(dataDir))
    if (startEnvironmentValue(p, "OMPI_COMM_WORLD_RANK") == "0") return p;
  return -1;
}

// Opens a session for `c` and stops its master rank (SIGSTOP); the rank's pid.
pid_t openSessionAndStopMaster(const Daemon& d, Client& c) {
  c.hello();
  c.openSession();
  const pid_t master = masterRank(d.dataDir);
  REQUIRE(master > 0);
  REQUIRE(::kill(master, SIGSTOP) == 0);
  return master;
}

}  // namespace

TEST_CASE("connections that never authenticate have their own limit, are closed after the handshake timeout and never keep a client out for long") {
  Daemon d(makeDataDir("strangers"), {"--max-sessions", "1", "--max-unauthenticated", "2", "--handshake-timeout", "2"},
           {}, logPath("strangers"));
  Client silent1(d.port), silent2(d.port);
  // Both strangers are counted before the third arrives.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  Client third(d.port);
  const auto refused = third.expectError(5);
  CHECK(refused.code == proto::ErrorCode::kLimitExceeded);
  CHECK(refused.text == "too many connections in handshake (2 of --max-unauthenticated 2); try again shortly");
  for (Client* s : {&silent1, &silent2}) {
    const auto e = s->expectError(15);
    CHECK(e.code == proto::ErrorCode::kTimeout);
    CHECK(e.text == "no authenticated Hello within 2 s (--handshake-timeout)");
  }
  silent1.closeNow();
  silent2.closeNow();
  // Their places are free again once their handlers are gone.
  const auto t = Clock::now();
  while (d.log().find("handler") == std::string::npos || since(t) < 0.5)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  Client c(d.port);
  c.hello();
  c.openSession();
  c.renderAndCheck();
}

TEST_CASE("a client without a job holds no session slot, and SessionOpen over --max-sessions is refused while the connection serves on") {
  Daemon d(makeDataDir("slots"), {"--max-sessions", "1"}, {}, logPath("slots"));
  Client a(d.port), b(d.port);
  a.hello();
  b.hello();
  b.send(proto::CatalogRequest{});
  CHECK(b.expect<proto::CatalogReply>().datasets.size() == 1);
  a.openSession();
  b.send(proto::SessionOpen{2, {}, ""});
  const auto e = b.expectError(10);
  CHECK(e.code == proto::ErrorCode::kLimitExceeded);
  CHECK(e.text == "too many sessions: all 1 of --max-sessions are open; try again when one ends");
  b.send(proto::StatusRequest{});
  CHECK(b.expect<proto::StatusReply>(10).entries.size() > 0);
  // The slot comes back when a's session ends, and b takes it.
  a.send(proto::Close{"done"});
  CHECK(a.expect<proto::Close>().reason == "bye");
  REQUIRE(secondsUntilJobGone(d.dataDir, 5) >= 0);
  b.openSession();
  b.renderAndCheck();
}

TEST_CASE("a client that never completes the secure channel is closed after the handshake timeout") {
  const fs::path dir = makeDataDir("tlsstall");
  const fs::path tokenFile = dir.parent_path() / ("token_tlsstall_" + std::to_string(::getpid()));
  std::ofstream(tokenFile) << "s3cret\n";
  fs::permissions(tokenFile, fs::perms::owner_read | fs::perms::owner_write);
  Daemon d(dir, {"--token-file", tokenFile.string(), "--handshake-timeout", "1"}, {}, logPath("tlsstall"));
  Client c(d.port);
  c.send(proto::Hello{"never finishes"});
  CHECK(c.expect<proto::Welcome>().authRequired);
  const Replies rest = readUntilClosed(c.fd, 15);
  CHECK(rest.closed);
  CHECK(d.log().find("closing: no authenticated Hello within 1 s (--handshake-timeout)") != std::string::npos);
}

TEST_CASE("a master that stopped reading neither wedges the handler nor hides its client leaving") {
  Daemon d(makeDataDir("wedged"), {}, {}, logPath("wedged"));
  Client c(d.port);
  const pid_t master = openSessionAndStopMaster(d, c);
  // Scenes of 1 MiB each until the master's socket and the handler's
  // buffer for it are full: the handler keeps reading and refuses the rest.
  const std::string padding(1 << 20, ' ');
  const auto scene = proto::encode(proto::SetScene{"", "{" + padding + "}"}, 7, 0);
  ::fcntl(c.fd, F_SETFL, ::fcntl(c.fd, F_GETFL) | O_NONBLOCK);
  std::size_t sent = 0;
  const auto t = Clock::now();
  while (since(t) < 8 && sent < 64 * scene.size()) {
    const ssize_t n = ::send(c.fd, scene.data() + sent % scene.size(), scene.size() - sent % scene.size(), MSG_NOSIGNAL);
    if (n > 0) sent += std::size_t(n);
    else std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ::fcntl(c.fd, F_SETFL, ::fcntl(c.fd, F_GETFL) & ~O_NONBLOCK);
  CHECK(sent == 64 * scene.size());
  const auto e = c.expectError(10);
  CHECK(e.code == proto::ErrorCode::kLimitExceeded);
  CHECK(e.text.find("bytes of requests already wait for the rendering job to read them; this one is dropped") !=
        std::string::npos);
  c.closeNow();
  const double gone = secondsUntilJobGone(d.dataDir, 10);
  ::kill(master, SIGKILL);  // in case the job outlived the test
  CHECK(gone >= 0);
  CHECK(fileComesToHold(d.logFile, "session ended", 5));
}

TEST_CASE("a stopped master rank is reported by number and host after the stall timeout and its job ends") {
  Daemon d(makeDataDir("stoppedmaster"), {"--stall-timeout", "2"}, {}, logPath("stoppedmaster"));
  Client c(d.port);
  const pid_t master = openSessionAndStopMaster(d, c);
  const auto e = c.expectError(30);
  CHECK(e.code == proto::ErrorCode::kRankFailed);
  CHECK(e.text.find("rank 0 on 127.0.0.1 sent nothing, not even its heartbeat, for 2 s (stopped or hung)") !=
        std::string::npos);
  const double gone = secondsUntilJobGone(d.dataDir, 15);
  ::kill(master, SIGKILL);
  CHECK(gone >= 0);
}
