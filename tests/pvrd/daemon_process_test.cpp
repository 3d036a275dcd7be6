// pvrd with real processes on an ephemeral loopback port: a real mpirun job
// renders, clients vanish, ranks die, hostile clients come and go, SIGTERM;
// a fake master (fake_master.h) sends frames pvrd must refuse.
#include <catch2/catch.hpp>

#include <random>

#include "auth.h"
#include "daemon_harness.h"
#include "fake_master.h"

using namespace pvr::daemon::testing;

TEST_CASE("a session starts an MPI job that renders a frame, and bad dataset names are refused") {
  Daemon d(makeDataDir("render"));
  Client c(d.port);
  c.hello();
  c.send(proto::CatalogRequest{});
  CHECK(c.expect<proto::CatalogReply>().datasets ==
        std::vector<proto::CatalogEntry>{{"ball", 1, "ball/ball.json", "raw+json", {32, 32, 32}, "uint8", ""}});
  c.openSession();
  c.renderAndCheck();
  c.send(proto::SetScene{"../render/ball/ball.json", ""});
  CHECK(c.expectError().code == proto::ErrorCode::kBadArgument);
  c.send(proto::SetScene{"/etc/passwd", ""});
  CHECK(c.expectError().code == proto::ErrorCode::kBadArgument);
  c.send(proto::RenderRotation{{0, 0, 1}, 0, 2, 4});
  for (int k = 0; k < 3; ++k) CHECK(c.expect<proto::ImageFrame>().frameNumber == std::uint32_t(k));
  c.send(proto::Close{"done"});
  CHECK(c.expect<proto::Close>().reason == "bye");
  CHECK(secondsUntilJobGone(d.dataDir, 2) >= 0);
}

TEST_CASE("a vanished client leaves no mpirun or pvr-node behind after 2 seconds") {
  Daemon d(makeDataDir("vanish"));
  Client c(d.port);
  c.hello();
  c.openSession();
  REQUIRE_FALSE(nodeProcesses(d.dataDir).empty());
  c.closeNow();
  const double gone = secondsUntilJobGone(d.dataDir, 2.0);
  WARN("client loss to job gone: " << gone << " s");
  CHECK(gone >= 0);
}

TEST_CASE("kill -9 of a rank gives the client an Error and the daemon serves on") {
  Daemon d(makeDataDir("killrank"));
  {
    Client c(d.port);
    c.hello();
    c.openSession();
    const auto nodes = nodeProcesses(d.dataDir);
    REQUIRE(nodes.size() == 2);
    ::kill(nodes.back(), SIGKILL);
    const auto e = c.expectError(10);
    CHECK(e.code == proto::ErrorCode::kRankFailed);
    WARN("rank failure reported as: " << e.text);
    CHECK(secondsUntilJobGone(d.dataDir, 3) >= 0);
  }
  Client again(d.port);
  again.hello();
  again.openSession();
  again.renderAndCheck();
}

TEST_CASE("200 hostile connections in a row each get their exact reply, then a normal session succeeds") {
  // Enough sessions that handlers not yet reaped never refuse the next one.
  Daemon d(makeDataDir("hostile"), {"--max-sessions", "16"});
  std::mt19937 rng(42);
  for (int i = 0; i < 200; ++i) {
    const int fd = connectTo(d.port);
    std::vector<std::uint8_t> bytes;
    std::optional<proto::ErrorCode> expected;  // none: closed without a word
    switch (i % 5) {
      case 0:  // garbage, whose first byte is not the magic's
        bytes.resize(1 + rng() % 200);
        for (auto& b : bytes) b = std::uint8_t(rng());
        if (bytes[0] == proto::kMagic[0]) bytes[0] = 'G';
        expected = proto::ErrorCode::kBadMagic;
        break;
      case 1: {  // half a frame, then the end of the stream
        const auto frame = proto::encode(proto::Hello{"half a frame of hello"}, 1);
        bytes.assign(frame.begin(), frame.begin() + std::ptrdiff_t(1 + rng() % (frame.size() - 1)));
        expected = proto::ErrorCode::kTruncatedFrame;
        break;
      }
      case 2:  // idle, then closed
        break;
      case 3:  // wrong magic
        bytes = proto::encode(proto::Hello{"x"}, 1);
        bytes[1] = 'Q';
        expected = proto::ErrorCode::kBadMagic;
        break;
      case 4: {  // absurd length
        bytes = proto::encode(proto::SetScene{"a", "b"}, 1);
        bytes[12] = bytes[13] = bytes[14] = bytes[15] = 0xff;
        expected = proto::ErrorCode::kFrameTooLarge;
        break;
      }
    }
    if (!bytes.empty()) REQUIRE(::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL) == ssize_t(bytes.size()));
    ::shutdown(fd, SHUT_WR);  // the end of the stream; the reply can still be read
    const Replies replies = readUntilClosed(fd, 30);
    ::close(fd);
    INFO("connection " << i << " (case " << i % 5 << "), " << bytes.size() << " bytes sent");
    REQUIRE(replies.closed);
    REQUIRE_FALSE(replies.error);
    if (!expected) {
      CHECK(replies.messages.empty());
      continue;
    }
    // Exactly an Error with the decoder's code, then Close; both about the
    // connection (request id 0) and FINAL; then the socket closes.
    REQUIRE(replies.messages.size() == 2);
    const auto* error = std::get_if<proto::ErrorMessage>(&replies.messages[0].message);
    REQUIRE(error);
    CHECK(error->code == *expected);
    CHECK(replies.messages[0].info == proto::FrameInfo{0, proto::kFlagFinal});
    CHECK(std::holds_alternative<proto::Close>(replies.messages[1].message));
    CHECK(replies.messages[1].info.requestId == 0);
  }
  Client c(d.port);
  c.hello();
  c.openSession();
  c.renderAndCheck();
  c.send(proto::Close{""});
}

TEST_CASE("frames the master sends over the limits are refused with an Error naming the limit, and the session serves on") {
  namespace fake = pvr::daemon::testing;
  Daemon d(makeDataDir("relay"), {"--mpirun", FAKE_MASTER_PATH});
  Client c(d.port);
  c.hello();
  c.openSession();
  const auto script = [&](std::string_view name) {
    c.send(proto::SetScene{"", std::string(name)});
    // Ok, and nothing before it: the dropped rest of a refused request never arrives.
    c.expect<proto::Ok>();
  };
  // The one answer to a RenderFrame under script `name`, FINAL for its request.
  const auto render = [&](std::string_view name) {
    script(name);
    const auto id = c.send(proto::RenderFrame{});
    auto d = c.next();
    REQUIRE(d);
    CHECK(d->info == proto::FrameInfo{id, proto::kFlagFinal});
    return std::move(*d);
  };
  const auto refusal = [&](std::string_view name) {
    const auto d = render(name);
    REQUIRE(std::holds_alternative<proto::ErrorMessage>(d.message));
    return std::get<proto::ErrorMessage>(d.message);
  };
  const auto renderGood = [&] {
    const auto d = render(fake::kScriptGood);
    REQUIRE(std::holds_alternative<proto::ImageFrame>(d.message));
    // Relayed as the master sent it: equal messages encode to equal bytes.
    const auto id = d.info.requestId;
    CHECK(proto::encode(d.message, id, proto::kFlagFinal) == proto::encode(fake::fakeGoodFrame(), id, proto::kFlagFinal));
  };
  renderGood();

  SECTION("an ImageFrame payload over the frame limit") {
    const auto e = refusal(fake::kScriptOversize);
    CHECK(e.code == proto::ErrorCode::kFrameTooLarge);
    CHECK_THAT(e.text, Catch::StartsWith("pvrd refused the rendering job's ImageFrame: frame too large: "));
    CHECK_THAT(e.text, Catch::Contains("ImageFrame payload of " + std::to_string(proto::kMaxFrameBytes - 15) +
                                       " bytes exceeds the limit of " + std::to_string(proto::kMaxFrameBytes - 16)));
  }
  SECTION("an ImageFrame whose pixel count disagrees with its size") {
    const auto e = refusal(fake::kScriptInconsistent);
    CHECK(e.code == proto::ErrorCode::kMalformedPayload);
    CHECK_THAT(e.text, Catch::Contains("needs 12 pixel bytes, got 11"));
  }
  renderGood();
  c.send(proto::Close{"done"});
  CHECK(c.expect<proto::Close>().reason == "bye");
  CHECK(secondsUntilJobGone(d.dataDir, 2) >= 0);
}

TEST_CASE("bytes from the master that are no frame end the job with an Error, and pvrd serves on") {
  Daemon d(makeDataDir("garbage"), {"--mpirun", FAKE_MASTER_PATH});
  {
    Client c(d.port);
    c.hello();
    c.openSession();
    c.send(proto::SetScene{"", std::string(pvr::daemon::testing::kScriptGarbage)});
    c.expect<proto::Ok>();
    c.send(proto::RenderFrame{});
    const auto e = c.expectError(10);
    CHECK(e.code == proto::ErrorCode::kRankFailed);
    CHECK_THAT(e.text, Catch::Contains("bad frame from the master") && Catch::Contains("bad magic"));
    CHECK(c.expect<proto::Close>(5).reason.size() > 0);
    CHECK(secondsUntilJobGone(d.dataDir, 3) >= 0);
  }
  Client again(d.port);
  again.hello();
  again.send(proto::CatalogRequest{});
  CHECK(again.expect<proto::CatalogReply>().datasets.size() == 1);
}

TEST_CASE("a malformed client frame gets an Error with the decoder's code and a Close") {
  Daemon d(makeDataDir("malformed"));
  Client c(d.port);
  const char text[] = "GET / HTTP/1.0\r\n\r\n";
  ::send(c.fd, text, sizeof text - 1, MSG_NOSIGNAL);
  CHECK(c.expectError(5).code == proto::ErrorCode::kBadMagic);
  CHECK(c.expect<proto::Close>(5).reason.size() > 0);
  CHECK_FALSE(c.next(5));
}

TEST_CASE("a wrong token fails the secure channel, the right one opens it, and nothing passes in the clear") {
  const fs::path dir = makeDataDir("token");
  const fs::path tokenFile = dir.parent_path() / ("token_" + std::to_string(::getpid()));
  std::ofstream(tokenFile) << "s3cret\n";
  fs::permissions(tokenFile, fs::perms::owner_read | fs::perms::owner_write);
  Daemon d(dir, {"--token-file", tokenFile.string()}, {}, logPath("token"));
  for (const std::string token : {"wrong", "s3cret"}) {
    Client c(d.port);
    c.send(proto::Hello{"daemon test"});
    CHECK(c.expect<proto::Welcome>().authRequired);
    c.secure(token);
    c.send(proto::CatalogRequest{});
    if (token == "wrong") {
      CHECK_FALSE(c.next(5));
      REQUIRE(c.channelFailure);
      CHECK(c.channelFailure->code == proto::ErrorCode::kAuthFailed);
    } else {
      CHECK(c.expect<proto::CatalogReply>().datasets.size() == 1);
      CHECK(c.channel->established());
    }
  }
  // A plain frame where the channel should start ends the connection.
  Client plain(d.port);
  plain.send(proto::Hello{"daemon test"});
  CHECK(plain.expect<proto::Welcome>().authRequired);
  plain.send(proto::CatalogRequest{});
  CHECK_FALSE(plain.next(5));
  const std::string log = d.log();
  CHECK(log.find("refused the client: secure channel: the handshake failed") != std::string::npos);
  CHECK(log.find("authenticated (secure channel)") != std::string::npos);
}

TEST_CASE("a stranger announcing a huge first frame is cut off after one control frame's worth of bytes") {
  Daemon d(makeDataDir("prehello"));
  Client c(d.port);
  std::vector<std::uint8_t> header(proto::kHeaderBytes);
  proto::writeHeader({proto::kProtocolVersion, proto::ImageFrame::kWire.type, 0, 1, 60u << 20},
                     std::span(header).first<proto::kHeaderBytes>());
  c.writeRaw(header);
  const std::vector<std::uint8_t> filler(200 << 10, 0);
  ::send(c.fd, filler.data(), filler.size(), MSG_NOSIGNAL);
  const auto e = c.expectError(5);
  CHECK(e.code == proto::ErrorCode::kLimitExceeded);
  CHECK(e.text == "more than " + std::to_string(proto::kHeaderBytes + proto::Limits{}.maxControlPayload) +
                      " bytes before Hello");
  // pvrd serves the next client.
  Client next(d.port);
  next.hello();
}

TEST_CASE("a client waiting for its own rotation is not idle") {
  Daemon d(makeDataDir("notidle"), {"--idle-timeout", "1"});
  Client c(d.port);
  c.hello();
  c.openSession();
  c.send(proto::SetScene{"ball/ball.json", R"({"image": {"width": 192, "height": 192}})"});
  c.expect<proto::Ok>();
  // Longer than the idle timeout, with nothing sent meanwhile.
  const auto started = Clock::now();
  c.send(proto::RenderRotation{{0, 0, 1}, 0, 299, 300});
  int frames = 0;
  while (frames < 300) {
    auto m = c.next(30);
    REQUIRE(m);
    if (const auto* e = std::get_if<proto::ErrorMessage>(&m->message)) FAIL("Error " << e->text);
    if (std::holds_alternative<proto::ImageFrame>(m->message)) ++frames;
  }
  INFO("the rotation took " << since(started) << " s");
  CHECK(since(started) > 1.0);  // else this test does not test the idle timer
  // Idle again afterwards: the timeout applies.
  CHECK(c.expectError(10).code == proto::ErrorCode::kTimeout);
}

TEST_CASE("a client streaming frames back to back is timed per frame, not from its first byte") {
  Daemon d(makeDataDir("streaming"), {"--frame-timeout", "1"});
  Client c(d.port);
  c.hello();
  // Each write ends half-way into the next StatusRequest, so pvrd's buffer
  // is never empty for 2.5 s while every frame completes within 0.25 s.
  const auto status = proto::encode(proto::StatusRequest{}, 7, 0);
  const std::size_t half = status.size() / 2;
  // One write: the end of a frame and the start of the next.
  std::vector<std::uint8_t> seam(status.begin() + std::ptrdiff_t(half), status.end());
  seam.insert(seam.end(), status.begin(), status.begin() + std::ptrdiff_t(half));
  c.writeRaw(std::span(status).first(half));
  for (int i = 0; i < 10; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
    c.writeRaw(seam);
  }
  c.writeRaw(std::span(status).subspan(half));
  for (int i = 0; i < 11; ++i) {
    auto m = c.next(5);
    REQUIRE(m);
    if (const auto* e = std::get_if<proto::ErrorMessage>(&m->message)) FAIL("Error " << e->text);
    CHECK(std::holds_alternative<proto::StatusReply>(m->message));
  }
}

TEST_CASE("escape sequences a client sends reach the log masked, never raw") {
  Daemon d(makeDataDir("escapes"), {}, {}, logPath("escapes"));
  Client c(d.port);
  c.send(proto::Hello{"\x1b]0;pwned\x07\x1b[2J\nfake log line"});
  c.expect<proto::Welcome>();
  c.send(proto::Close{"done"});
  c.expect<proto::Close>();
  const std::string log = d.log();
  CHECK(log.find("hello from '\\x1b]0;pwned\\x07\\x1b[2J\\x0afake log line'") != std::string::npos);
  CHECK(log.find('\x1b') == std::string::npos);
  CHECK(log.find('\x07') == std::string::npos);
}

TEST_CASE("a token file other users may read is refused, saying how to fix it") {
  const fs::path dir = makeDataDir("tokenmode");
  const fs::path tokenFile = dir.parent_path() / ("token_open_" + std::to_string(::getpid()));
  std::ofstream(tokenFile) << "s3cret\n";
  fs::permissions(tokenFile, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read |
                                 fs::perms::others_read);
  // pvrd refuses to start: its exit status and what it printed.
  const std::string command = std::string(PVRD_PATH) + " --listen 127.0.0.1:0 --data-dir " + dir.string() +
                              " --token-file " + tokenFile.string() + " 2>&1";
  FILE* p = ::popen(command.c_str(), "r");
  REQUIRE(p);
  std::string output;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p)) output += buf;
  const int status = ::pclose(p);
  CHECK(WEXITSTATUS(status) == 2);
  CHECK(output.find("token file " + tokenFile.string() + " has mode 0644: other users may read or change it; "
                    "make it private with: chmod 600 " + tokenFile.string()) != std::string::npos);
}

TEST_CASE("a client stalled in the middle of a frame is timed out") {
  Daemon d(makeDataDir("stall"), {"--idle-timeout", "2"});
  Client c(d.port);
  const auto frame = proto::encode(proto::Hello{"stalled"}, 1);
  ::send(c.fd, frame.data(), 5, MSG_NOSIGNAL);
  CHECK(c.expectError(15).code == proto::ErrorCode::kTimeout);
}

TEST_CASE("SIGTERM on pvrd ends every job and pvrd exits 0") {
  Daemon d(makeDataDir("sigterm"));
  Client c(d.port);
  c.hello();
  c.openSession();
  REQUIRE_FALSE(nodeProcesses(d.dataDir).empty());
  const auto t = Clock::now();
  CHECK(d.stop() == 0);
  WARN("pvrd stopped in " << since(t) << " s");
  CHECK(secondsUntilJobGone(d.dataDir, 1) >= 0);
}
