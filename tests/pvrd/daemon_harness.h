// The harness of the daemon process tests: a data directory, pvrd run as a
// child on an ephemeral loopback port (its log kept in a file), a client
// speaking the protocol, and the job's processes found in /proc.
#pragma once

#include <catch2/catch.hpp>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <chrono>
#include <cmath>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <thread>

#include "../proc_files.h"
#include "pvr_protocol.h"
#include "secure_channel.h"

namespace pvr::daemon::testing {

namespace fs = std::filesystem;
namespace proto = pvr::proto;
using Clock = std::chrono::steady_clock;

inline double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// A data directory with a 32^3 uint8 sphere as raw + JSON sidecar.
inline fs::path makeDataDir(const std::string& tag) {
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
inline std::vector<pid_t> jobProcesses(const fs::path& dataDir) {
  std::vector<pid_t> pids;
  for (const pid_t pid : pvr::testing::allPids()) {
    std::string cmd = pvr::testing::procFile(pid, "cmdline");
    std::replace(cmd.begin(), cmd.end(), '\0', ' ');
    if (cmd.find("--connect") != std::string::npos && cmd.find(dataDir.string()) != std::string::npos &&
        pvr::testing::processRuns(pid))
      pids.push_back(pid);
  }
  return pids;
}

inline std::vector<pid_t> nodeProcesses(const fs::path& dataDir) {
  std::vector<pid_t> out;
  for (pid_t p : jobProcesses(dataDir))
    if (pvr::testing::procFile(p, "comm").find("pvr-node") != std::string::npos) out.push_back(p);
  return out;
}

// Seconds until no process of the job is left, or -1 after `limit` seconds.
inline double secondsUntilJobGone(const fs::path& dataDir, double limit) {
  const auto t = Clock::now();
  while (since(t) < limit) {
    if (jobProcesses(dataDir).empty()) return since(t);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return -1;
}

using pvr::testing::procEntries;

// The value of `name` in the environment process `pid` started with; "" if unset.
inline std::string startEnvironmentValue(pid_t pid, const std::string& name) {
  for (const std::string& e : procEntries(pid, "environ"))
    if (e.rfind(name + "=", 0) == 0) return e.substr(name.size() + 1);
  return {};
}

// True once the file at `path` holds `text`; false after `limit` seconds.
inline bool fileComesToHold(const fs::path& path, const std::string& text, double limit) {
  const auto t = Clock::now();
  while (since(t) < limit) {
    std::ifstream in(path);
    const std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (content.find(text) != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

using Environment = std::vector<std::pair<std::string, std::string>>;

// A file for one test's pvrd log (Daemon's `log`), unique to this process.
inline fs::path logPath(const std::string& tag) {
  return fs::path(PVR_TEST_TMP) / ("pvrd_" + tag + "_" + std::to_string(::getpid()) + ".log");
}

// pvrd on 127.0.0.1:0 with `extra` options and `environment` added to the
// test's; its log goes to `logFile` when one is named.
struct Daemon {
  pid_t pid = -1;
  int port = 0;
  fs::path dataDir;
  fs::path logFile;
  explicit Daemon(const fs::path& dir, std::vector<std::string> extra = {}, const Environment& environment = {},
                  fs::path log = {})
      : dataDir(dir), logFile(std::move(log)) {
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
      if (!logFile.empty()) {
        const int fd = ::open(logFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
        if (fd >= 0) ::dup2(fd, 2);
      }
      for (const auto& [name, value] : environment) ::setenv(name.c_str(), value.c_str(), 1);
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
  // What pvrd logged so far.
  std::string log() const {
    std::ifstream in(logFile);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }
};

// Everything a peer sent until it closed the connection (or `seconds` passed).
struct Replies {
  std::vector<proto::Decoded> messages;
  std::optional<proto::ProtocolError> error;  // the replies did not decode
  bool closed = false;
};

inline Replies readUntilClosed(int fd, double seconds) {
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

inline int connectTo(int port) {
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
  std::unique_ptr<proto::SecureChannel> channel;  // after secure()
  std::optional<proto::ProtocolError> channelFailure;  // what the channel refused
  std::uint32_t nextId = 1;
  explicit Client(int port) : fd(connectTo(port)) {}
  ~Client() { closeNow(); }
  void closeNow() {
    if (fd >= 0) ::close(fd);
    fd = -1;
  }
  std::uint32_t send(const proto::Message& m) {
    const auto bytes = proto::encode(m, nextId, 0);
    if (channel) {
      REQUIRE_FALSE(channel->send(bytes));
      writeRaw(channel->takeOutgoing());
    } else {
      writeRaw(bytes);
    }
    return nextId++;
  }
  void writeRaw(std::span<const std::uint8_t> bytes) {
    if (bytes.empty()) return;
    REQUIRE(::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL) == ssize_t(bytes.size()));
  }
  // As pvrsh after a Welcome that asks for a token: the secure channel
  // keyed by `token`; frames sent from now on wait for its handshake.
  void secure(const std::string& token) {
    channel = std::make_unique<proto::SecureChannel>(proto::SecureChannel::Role::kClient, token,
                                                     proto::kClientPurpose);
    writeRaw(channel->takeOutgoing());
  }
  // Why the last next() returned nothing, for a failing test's report.
  std::string ended;
  // The next message, or nullopt at end of stream or after `seconds`.
  std::optional<proto::Decoded> next(double seconds = 60) {
    const auto t = Clock::now();
    for (;;) {
      if (auto d = decoder.pop()) return d;
      if (decoder.error()) {
        ended = "the replies did not decode: " + decoder.error()->text;
        return std::nullopt;
      }
      if (since(t) > seconds) {
        ended = "nothing came within " + std::to_string(seconds) + " s";
        return std::nullopt;
      }
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, 100) <= 0) continue;
      std::uint8_t buf[65536];
      const ssize_t n = ::read(fd, buf, sizeof buf);
      if (n <= 0) {
        ended = n == 0 ? "the peer closed the connection" : std::string("read: ") + std::strerror(errno);
        return std::nullopt;
      }
      if (!channel) {
        decoder.feed(std::span(buf, std::size_t(n)));
        continue;
      }
      channelFailure = channel->receive(std::span(buf, std::size_t(n)));
      writeRaw(channel->takeOutgoing());  // handshake replies, or the alert
      if (channelFailure) {
        ended = "the secure channel failed: " + channelFailure->text;
        return std::nullopt;
      }
      decoder.feed(channel->takeIncoming());
    }
  }
  template <class T>
  T expect(double seconds = 60) {
    auto d = next(seconds);
    INFO("waiting for " << T::kWire.name << ": " << ended);
    REQUIRE(d);
    if (const auto* e = std::get_if<proto::ErrorMessage>(&d->message)) FAIL("Error " << int(e->code) << ": " << e->text);
    INFO("got " << proto::messageInfo(d->message).name);
    REQUIRE(std::holds_alternative<T>(d->message));
    return std::get<T>(d->message);
  }
  proto::ErrorMessage expectError(double seconds = 60) {
    for (;;) {
      auto d = next(seconds);
      INFO("waiting for an Error: " << ended);
      REQUIRE(d);
      if (auto* e = std::get_if<proto::ErrorMessage>(&d->message)) return *e;
    }
  }
  void hello() {
    send(proto::Hello{"daemon test"});
    CHECK_FALSE(expect<proto::Welcome>().authRequired);
  }
  void openSession() {
    send(proto::SessionOpen{2, {}, ""});
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


}  // namespace pvr::daemon::testing
