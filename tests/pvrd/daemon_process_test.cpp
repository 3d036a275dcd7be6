// pvrd with real processes on an ephemeral loopback port: a real mpirun job
// renders, clients vanish, ranks die, hostile clients come and go, SIGTERM;
// a fake master (fake_master.h) sends frames pvrd must refuse.
#include <catch2/catch.hpp>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include "auth.h"
#include "fake_master.h"
#include "pvr_protocol.h"

namespace fs = std::filesystem;
namespace proto = pvr::proto;
using Clock = std::chrono::steady_clock;

namespace {

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// A data directory with a 32^3 uint8 sphere as raw + JSON sidecar.
fs::path makeDataDir(const std::string& tag) {
  const fs::path dir = fs::path(PVR_TEST_TMP) / ("pvrd_" + tag + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "ball");
  std::vector<std::uint8_t> v(32 * 32 * 32);
  for (int z = 0; z < 32; ++z)
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) {
        const double r = std::sqrt((x - 15.5) * (x - 15.5) + (y - 15.5) * (y - 15.5) + (z - 15.5) * (z - 15.5));
        v[std::size_t((z * 32 + y) * 32 + x)] = std::uint8_t(r < 12 ? 255 - r * 10 : 0);
      }
  std::ofstream(dir / "ball" / "ball.raw", std::ios::binary).write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size()));
  std::ofstream(dir / "ball" / "ball.json") << R"({"dims": [32, 32, 32], "dtype": "uint8", "spacing": [1, 1, 1],
    "origin": [0, 0, 0], "raw_file": "ball.raw", "endian": "little"})";
  return dir;
}

// Pids of mpirun and pvr-node processes started for this data directory.
std::vector<pid_t> jobProcesses(const fs::path& dataDir) {
  std::vector<pid_t> pids;
  for (const auto& e : fs::directory_iterator("/proc")) {
    const pid_t pid = pid_t(std::atoi(e.path().filename().c_str()));
    if (pid <= 0) continue;
    std::ifstream in(e.path() / "cmdline", std::ios::binary);
    std::string cmd((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::replace(cmd.begin(), cmd.end(), '\0', ' ');
    if (cmd.find("--connect") != std::string::npos && cmd.find(dataDir.string()) != std::string::npos) {
      std::ifstream stat(e.path() / "stat");
      std::string s((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
      const auto close = s.rfind(')');
      if (close != std::string::npos && s.size() > close + 2 && s[close + 2] == 'Z') continue;  // zombie
      pids.push_back(pid);
    }
  }
  return pids;
}

std::vector<pid_t> nodeProcesses(const fs::path& dataDir) {
  std::vector<pid_t> out;
  for (pid_t p : jobProcesses(dataDir)) {
    std::ifstream in("/proc/" + std::to_string(p) + "/comm");
    std::string comm;
    std::getline(in, comm);
    if (comm.find("pvr-node") != std::string::npos) out.push_back(p);
  }
  return out;
}

// Seconds until no process of the job is left, or -1 after `limit` seconds.
double secondsUntilJobGone(const fs::path& dataDir, double limit) {
  const auto t = Clock::now();
  while (since(t) < limit) {
    if (jobProcesses(dataDir).empty()) return since(t);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return -1;
}

struct Daemon {
  pid_t pid = -1;
  int port = 0;
  fs::path dataDir;
  explicit Daemon(const fs::path& dir, std::vector<std::string> extra = {}) : dataDir(dir) {
    int out[2];
    REQUIRE(::pipe(out) == 0);
    std::vector<std::string> args{PVRD_PATH, "--listen", "127.0.0.1:0", "--data-dir", dir.string(), "--node",
                                  PVR_NODE_PATH, "--max-ranks", "2", "--max-sessions", "2"};
    args.insert(args.end(), extra.begin(), extra.end());
    pid = ::fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
      ::dup2(out[1], 1);
      ::close(out[0]);
      ::close(out[1]);
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
    ::close(out[1]);
    std::string line;
    char c;
    while (::read(out[0], &c, 1) == 1 && c != '\n') line += c;
    ::close(out[0]);
    const auto colon = line.rfind(':');
    REQUIRE(line.rfind("pvrd listening on 127.0.0.1:", 0) == 0);
    port = std::atoi(line.c_str() + colon + 1);
    REQUIRE(port > 0);
  }
  int stop() {
    if (pid <= 0) return -1;
    ::kill(pid, SIGTERM);
    int status = 0;
    ::waitpid(pid, &status, 0);
    pid = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }
  ~Daemon() { stop(); }
};

// Everything a peer sent until it closed the connection (or `seconds` passed).
struct Replies {
  std::vector<proto::Decoded> messages;
  std::optional<proto::ProtocolError> error;  // the replies did not decode
  bool closed = false;
};

Replies readUntilClosed(int fd, double seconds) {
  Replies replies;
  proto::FrameDecoder decoder;
  const auto t = Clock::now();
  while (since(t) < seconds) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    std::uint8_t buf[65536];
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n <= 0) {
      replies.closed = true;
      break;
    }
    decoder.feed(std::span(buf, std::size_t(n)));
    while (auto d = decoder.pop()) replies.messages.push_back(std::move(*d));
  }
  replies.error = decoder.error() ? decoder.error() : decoder.endOfStream();
  return replies;
}

int connectTo(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(std::uint16_t(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  REQUIRE(::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0);
  return fd;
}

struct Client {
  int fd;
  proto::FrameDecoder decoder;
  std::uint32_t nextId = 1;
  explicit Client(int port) : fd(connectTo(port)) {}
  ~Client() { closeNow(); }
  void closeNow() {
    if (fd >= 0) ::close(fd);
    fd = -1;
  }
  std::uint32_t send(const proto::Message& m) {
    const auto bytes = proto::encode(m, nextId, 0);
    REQUIRE(::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL) == ssize_t(bytes.size()));
    return nextId++;
  }
  // The next message, or nullopt at end of stream or after `seconds`.
  std::optional<proto::Decoded> next(double seconds = 60) {
    const auto t = Clock::now();
    for (;;) {
      if (auto d = decoder.pop()) return d;
      if (decoder.error() || since(t) > seconds) return std::nullopt;
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, 100) <= 0) continue;
      std::uint8_t buf[65536];
      const ssize_t n = ::read(fd, buf, sizeof buf);
      if (n <= 0) return std::nullopt;
      decoder.feed(std::span(buf, std::size_t(n)));
    }
  }
  template <class T>
  T expect(double seconds = 60) {
    auto d = next(seconds);
    REQUIRE(d);
    if (const auto* e = std::get_if<proto::ErrorMessage>(&d->message)) FAIL("Error " << int(e->code) << ": " << e->text);
    REQUIRE(std::holds_alternative<T>(d->message));
    return std::get<T>(d->message);
  }
  proto::ErrorMessage expectError(double seconds = 60) {
    for (;;) {
      auto d = next(seconds);
      REQUIRE(d);
      if (auto* e = std::get_if<proto::ErrorMessage>(&d->message)) return *e;
    }
  }
  void hello() {
    send(proto::Hello{"daemon test"});
    CHECK_FALSE(expect<proto::Welcome>().authRequired);
  }
  void openSession() {
    send(proto::SessionOpen{2, {}});
    CHECK(expect<proto::SessionReady>().rankCount == 2);
  }
  void renderAndCheck() {
    send(proto::SetScene{"ball/ball.json", R"({"image": {"width": 64, "height": 64, "background": [0, 0, 0, 1]}})"});
    expect<proto::Ok>();
    send(proto::RenderFrame{});
    const auto f = expect<proto::ImageFrame>();
    CHECK(f.width == 64);
    CHECK(f.height == 64);
    REQUIRE(f.compression == proto::Compression::kZlib);
    std::vector<std::uint8_t> raw(64 * 64 * 4);
    uLongf size = raw.size();
    REQUIRE(uncompress(raw.data(), &size, f.pixels.data(), uLong(f.pixels.size())) == Z_OK);
    REQUIRE(size == raw.size());
    int lit = 0;
    for (std::size_t i = 0; i < raw.size(); i += 4) lit += raw[i] > 0;
    CHECK(lit > 100);
  }
};

}  // namespace

TEST_CASE("a session starts an MPI job that renders a frame, and bad dataset names are refused") {
  Daemon d(makeDataDir("render"));
  Client c(d.port);
  c.hello();
  c.send(proto::CatalogRequest{});
  CHECK(c.expect<proto::CatalogReply>().datasets == std::vector<std::string>{"ball/ball.json"});
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

TEST_CASE("a wrong token is refused and the right one accepted") {
  const fs::path dir = makeDataDir("token");
  const fs::path tokenFile = dir.parent_path() / ("token_" + std::to_string(::getpid()));
  std::ofstream(tokenFile) << "s3cret\n";
  Daemon d(dir, {"--token-file", tokenFile.string()});
  for (const std::string token : {"wrong", "s3cret"}) {
    Client c(d.port);
    c.send(proto::Hello{"daemon test"});
    CHECK(c.expect<proto::Welcome>().authRequired);
    const auto challenge = c.expect<proto::AuthChallenge>();
    c.send(proto::AuthResponse{pvr::daemon::hmacSha256(token, challenge.nonce)});
    if (token == "wrong") {
      CHECK(c.expectError(5).code == proto::ErrorCode::kAuthFailed);
      CHECK(c.expect<proto::Close>(5).reason.size() > 0);
    } else {
      c.expect<proto::Ok>();
      c.send(proto::CatalogRequest{});
      CHECK(c.expect<proto::CatalogReply>().datasets.size() == 1);
    }
  }
}

TEST_CASE("extra connections over --max-sessions get too many sessions") {
  Daemon d(makeDataDir("maxsessions"));
  Client a(d.port), b(d.port);
  a.hello();
  b.hello();
  Client c(d.port);
  const auto e = c.expectError(5);
  CHECK(e.code == proto::ErrorCode::kLimitExceeded);
  CHECK(e.text == "too many sessions");
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
