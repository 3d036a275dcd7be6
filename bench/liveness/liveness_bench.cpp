// pvr-bench-liveness: how soon a pvr-node --server job answers while it
// renders (issue 15 finding 8: Status and Cancel within 200 ms).
//
//   pvr-bench-liveness --data-dir DIR --dataset NAME [--np 2] [--trials 5]
//       [--size 512] [--step S] [--rotation 36] [--node PVR_NODE] [--mpirun PATH]
//
// Plays pvrd's session handler: listens on loopback, starts mpirun with a
// job secret, completes the secure channel and checks the JobHello. Then:
//   slow frame  one frame at --size with --step and early termination off,
//               timed (Y s);
//   status      --trials times: RenderFrame, wait Y/2, StatusRequest; the
//               time to its StatusReply, and whether it came before the frame;
//   cancel      --trials times: RenderFrame, wait Y/2, Cancel; the time to the
//               Cancel's Ok and to the frame's end (Error CANCELLED, or the
//               frame when Cancel cannot stop it);
//   rotation    --rotation frames at step 0.48 (about the CT head's default),
//               early termination 0.99: frames/s, for before/after comparisons.
// Prints a table and CSV lines (kind,trial,ms,note) on stdout.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "pvr_protocol.h"
#include "secure_channel.h"

namespace {

using namespace pvr;
using Clock = std::chrono::steady_clock;

[[noreturn]] void die(const std::string& why) {
  std::fprintf(stderr, "pvr-bench-liveness: %s\n", why.c_str());
  std::exit(1);
}

double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// The handler's end of one job, inside the secure channel.
class Job {
 public:
  Job(const std::string& mpirun, const std::string& node, int np, const std::string& dataDir) {
    const std::string secret(64, 'a');
    const int listenFd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::bind(listenFd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 || ::listen(listenFd, 1) != 0)
      die("cannot listen on loopback");
    socklen_t len = sizeof addr;
    ::getsockname(listenFd, reinterpret_cast<sockaddr*>(&addr), &len);
    pid_ = ::fork();
    if (pid_ == 0) {
      ::setenv(proto::kJobSecretVariable, secret.c_str(), 1);
      std::vector<std::string> args{mpirun, "--oversubscribe", "--bind-to", "none", "-x", proto::kJobSecretVariable,
                                    "-np", std::to_string(np), node, "--server", "--connect",
                                    "127.0.0.1:" + std::to_string(ntohs(addr.sin_port)), "--data-dir", dataDir};
      std::vector<char*> av;
      for (auto& a : args) av.push_back(a.data());
      av.push_back(nullptr);
      ::execvp(av[0], av.data());
      ::_exit(127);
    }
    pollfd p{listenFd, POLLIN, 0};
    if (::poll(&p, 1, 60000) != 1) die("the master did not connect within 60 s");
    fd_ = ::accept(listenFd, nullptr, nullptr);
    ::close(listenFd);
    channel_ = std::make_unique<proto::SecureChannel>(proto::SecureChannel::Role::kServer, secret,
                                                      proto::kConnectBackPurpose);
    if (!std::holds_alternative<proto::JobHello>(receive().message)) die("the master's first frame is no JobHello");
  }
  ~Job() {
    send(proto::Close{"done"});
    int status = 0;
    ::waitpid(pid_, &status, 0);
  }
  std::uint32_t send(const proto::Message& m) {
    if (channel_->send(proto::encode(m, ++id_, proto::kFlagFinal))) die("secure channel failed");
    const auto bytes = channel_->takeOutgoing();
    if (::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL) != ssize_t(bytes.size())) die("send failed");
    return id_;
  }
  // The next frame but Heartbeats.
  proto::Decoded receive() {
    for (;;) {
      while (auto d = decoder_.pop())
        if (!std::holds_alternative<proto::Heartbeat>(d->message)) return *d;
      if (decoder_.error()) die("bad frame: " + decoder_.error()->text);
      std::uint8_t buf[1 << 16];
      const ssize_t n = ::read(fd_, buf, sizeof buf);
      if (n <= 0) die("the master closed the link");
      if (channel_->receive(std::span(buf, std::size_t(n)))) die("secure channel failed");
      const auto out = channel_->takeOutgoing();
      if (!out.empty()) ::send(fd_, out.data(), out.size(), MSG_NOSIGNAL);
      decoder_.feed(channel_->takeIncoming());
    }
  }
  template <class T>
  T expect() {
    const auto d = receive();
    if (const auto* e = std::get_if<proto::ErrorMessage>(&d.message)) die("error from the master: " + e->text);
    if (!std::holds_alternative<T>(d.message)) die("unexpected answer");
    return std::get<T>(d.message);
  }

 private:
  pid_t pid_ = -1;
  int fd_ = -1;
  std::uint32_t id_ = 0;
  std::unique_ptr<proto::SecureChannel> channel_;
  proto::FrameDecoder decoder_;
};

void row(const char* kind, int trial, double ms, const std::string& note) {
  std::printf("csv,%s,%d,%.1f,%s\n", kind, trial, ms, note.c_str());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  std::string dataDir, dataset, node = PVR_NODE_PATH, mpirun = "mpirun";
  int np = 2, trials = 5, size = 512, rotation = 36;
  double step = 0.05;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) die(a + " needs a value");
      return argv[++i];
    };
    if (a == "--data-dir") dataDir = value();
    else if (a == "--dataset") dataset = value();
    else if (a == "--np") np = std::atoi(value().c_str());
    else if (a == "--trials") trials = std::atoi(value().c_str());
    else if (a == "--size") size = std::atoi(value().c_str());
    else if (a == "--step") step = std::atof(value().c_str());
    else if (a == "--rotation") rotation = std::atoi(value().c_str());
    else if (a == "--node") node = value();
    else if (a == "--mpirun") mpirun = value();
    else die("unknown argument " + a);
  }
  if (dataDir.empty() || dataset.empty()) die("--data-dir and --dataset are required");

  Job job(mpirun, node, np, dataDir);
  job.send(proto::SessionOpen{std::uint32_t(np), {}, ""});
  job.expect<proto::SessionReady>();
  // About half the CT head's voxel spacing, as the scene's default step.
  const nlohmann::json fast = {{"sampling", {{"step", 0.48}, {"early_termination", 0.99}}}};
  const nlohmann::json slow = {{"image", {{"width", size}, {"height", size}}},
                               {"sampling", {{"step", step}, {"early_termination", 1}}}};
  job.send(proto::SetScene{dataset, slow.dump()});
  job.expect<proto::Ok>();

  // The slow frame, twice: the first warms up.
  double frameMs = 0;
  for (int k = 0; k < 2; ++k) {
    const auto start = Clock::now();
    job.send(proto::RenderFrame{});
    job.expect<proto::ImageFrame>();
    frameMs = msSince(start);
  }
  row("frame", 0, frameMs, std::to_string(size) + "px step " + std::to_string(step));
  const auto halfFrame = std::chrono::duration<double, std::milli>(frameMs / 2);

  // Status in the middle of a frame.
  std::vector<double> status, cancelOk, cancelEnd;
  for (int t = 0; t < trials; ++t) {
    const auto render = job.send(proto::RenderFrame{});
    std::this_thread::sleep_for(halfFrame);
    const auto asked = Clock::now();
    const auto id = job.send(proto::StatusRequest{});
    bool before = false, frameSeen = false, answered = false;
    while (!answered || !frameSeen) {
      const auto d = job.receive();
      if (d.info.requestId == id) {
        status.push_back(msSince(asked));
        answered = true;
        before = !frameSeen;
      } else if (d.info.requestId == render) {
        frameSeen = true;
      }
    }
    row("status", t, status.back(), before ? "before the frame" : "after the frame");
  }
  // Cancel in the middle of a frame.
  for (int t = 0; t < trials; ++t) {
    const auto render = job.send(proto::RenderFrame{});
    std::this_thread::sleep_for(halfFrame);
    const auto asked = Clock::now();
    const auto id = job.send(proto::Cancel{render});
    bool ok = false, ended = false;
    std::string how;
    while (!ok || !ended) {
      const auto d = job.receive();
      if (d.info.requestId == id) {
        cancelOk.push_back(msSince(asked));
        ok = true;
      } else if (d.info.requestId == render) {
        cancelEnd.push_back(msSince(asked));
        ended = true;
        how = std::holds_alternative<proto::ErrorMessage>(d.message) ? std::get<proto::ErrorMessage>(d.message).text
                                                                      : "the frame came (not stopped)";
      }
    }
    row("cancel_ok", t, cancelOk.back(), "");
    row("cancel_end", t, cancelEnd.back(), how);
  }
  // A rotation at the dataset's default step.
  job.send(proto::SetScene{"", fast.dump()});
  job.expect<proto::Ok>();
  job.send(proto::RenderFrame{});
  job.expect<proto::ImageFrame>();
  const auto start = Clock::now();
  job.send(proto::RenderRotation{{0, 0, 1}, 0, rotation - 1, std::uint32_t(rotation)});
  for (int k = 0; k < rotation; ++k) job.expect<proto::ImageFrame>();
  const double rotationMs = msSince(start);
  row("rotation", 0, rotationMs / rotation, std::to_string(rotation) + " frames, " + std::to_string(size) + "px");

  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
  };
  const auto worst = [](const std::vector<double>& v) { return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()); };
  std::printf("\n%-34s %10s %10s\n", "during a frame of", "median", "max");
  std::printf("%-34s %9.0f ms\n", "slow frame (whole)", frameMs);
  std::printf("%-34s %7.1f ms %7.1f ms\n", "Status -> StatusReply", median(status), worst(status));
  std::printf("%-34s %7.1f ms %7.1f ms\n", "Cancel -> Ok", median(cancelOk), worst(cancelOk));
  std::printf("%-34s %7.1f ms %7.1f ms\n", "Cancel -> end of the frame", median(cancelEnd), worst(cancelEnd));
  std::printf("%-34s %7.1f ms  (%.2f frames/s)\n", "rotation, per frame", rotationMs / rotation, 1000.0 * rotation / rotationMs);
  return 0;
}
