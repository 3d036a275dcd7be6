#include "session.h"

#include <dirent.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <deque>
#include <map>
#include <regex>
#include <set>

#include "auth.h"
#include "catalog.h"
#include "pvr_protocol.h"
#include "sys.h"

namespace pvr::daemon {
namespace {

using proto::ErrorCode;

volatile sig_atomic_t gStop = 0;
void onStop(int) { gStop = 1; }

constexpr double kMasterConnectSeconds = 60;
constexpr std::size_t kStderrTail = 4096;

// Every process descended from `root`, read from /proc.
std::set<pid_t> descendants(pid_t root) {
  std::multimap<pid_t, pid_t> children;
  if (DIR* d = ::opendir("/proc")) {
    while (dirent* e = ::readdir(d)) {
      const pid_t pid = pid_t(std::atoi(e->d_name));
      if (pid <= 0) continue;
      char path[64];
      std::snprintf(path, sizeof path, "/proc/%d/stat", pid);
      FILE* f = std::fopen(path, "r");
      if (!f) continue;
      char buf[512];
      const std::size_t n = std::fread(buf, 1, sizeof buf - 1, f);
      std::fclose(f);
      buf[n] = 0;
      const char* close = std::strrchr(buf, ')');
      int ppid = 0;
      if (close && std::sscanf(close + 1, " %*c %d", &ppid) == 1) children.emplace(ppid, pid);
    }
    ::closedir(d);
  }
  std::set<pid_t> found;
  std::deque<pid_t> frontier{root};
  while (!frontier.empty()) {
    const pid_t p = frontier.front();
    frontier.pop_front();
    for (auto [it, end] = children.equal_range(p); it != end; ++it)
      if (found.insert(it->second).second) frontier.push_back(it->second);
  }
  return found;
}

class Session {
 public:
  Session(const SessionConfig& c, int fd) : cfg_(c), opt_(*c.options), client_(fd) {}
  int run();

 private:
  void log(const std::string& event) const { logEvent(cfg_.id, event); }
  bool sendClient(const proto::Message& m, std::uint32_t id, bool final = true);
  bool sendClientBytes(std::span<const std::uint8_t> frame);
  void replyError(ErrorCode code, const std::string& text, std::uint32_t id) {
    sendClient(proto::ErrorMessage{code, text}, id);
  }
  void endConnection(ErrorCode code, const std::string& text, std::uint32_t id);
  void onClient(proto::Decoded frame);
  void onMaster(proto::RelayItem item);
  void refuseMasterFrame(const proto::RefusedFrame& refused);
  void forward(const proto::Message& m, std::uint32_t id);
  bool launch(std::uint32_t ranks, std::string& error);
  void drainStderr();
  void jobEnded(const std::string& why);
  void teardown();

  const SessionConfig& cfg_;
  const DaemonOptions& opt_;
  int client_;
  int master_ = -1, listen_ = -1, stderr_ = -1;
  pid_t job_ = -1;
  bool jobExited_ = false;
  int jobStatus_ = 0;
  std::string stderrTail_;
  proto::FrameDecoder fromClient_;
  // Master frames are checked and passed on as they came, not re-encoded.
  proto::FrameRelay fromMaster_;
  // Requests answered with an Error after pvrd refused a master frame: the
  // master's further frames for them are dropped until its FINAL one.
  std::set<std::uint32_t> refusedRequests_;
  bool greeted_ = false, authenticated_ = false, done_ = false;
  Nonce nonce_{};
  std::deque<std::vector<std::uint8_t>> pendingToMaster_;
  double launchedAt_ = 0;
};

bool Session::sendClient(const proto::Message& m, std::uint32_t id, bool final) {
  return sendClientBytes(proto::encode(m, id, final ? proto::kFlagFinal : 0));
}

bool Session::sendClientBytes(std::span<const std::uint8_t> frame) {
  if (client_ < 0) return false;
  std::string error;
  if (writeAll(client_, frame, error)) return true;
  log("client write failed: " + error);
  ::close(client_);
  client_ = -1;
  done_ = true;
  return false;
}

void Session::endConnection(ErrorCode code, const std::string& text, std::uint32_t id) {
  log("closing: " + std::string(proto::errorCodeName(code)) + ": " + text);
  replyError(code, text, id);
  sendClient(proto::Close{text}, 0);
  done_ = true;
}

void Session::forward(const proto::Message& m, std::uint32_t id) {
  auto bytes = proto::encode(m, id, 0);
  if (master_ < 0) {
    pendingToMaster_.push_back(std::move(bytes));
    return;
  }
  std::string error;
  if (!writeAll(master_, bytes, error)) jobEnded("master write failed: " + error);
}

void Session::onClient(proto::Decoded frame) {
  const std::uint32_t id = frame.info.requestId;
  const proto::Message& m = frame.message;
  if (std::holds_alternative<proto::Close>(m)) {
    log("client sent Close");
    if (master_ >= 0) forward(m, id);
    sendClient(proto::Close{"bye"}, 0);
    done_ = true;
    return;
  }
  if (!greeted_) {
    if (!std::holds_alternative<proto::Hello>(m)) return endConnection(ErrorCode::kUnexpectedMessage, "expected Hello", id);
    greeted_ = true;
    log("hello from '" + std::get<proto::Hello>(m).software + "'");
    const bool auth = !cfg_.token.empty();
    sendClient(proto::Welcome{"pvrd 0.1", std::uint32_t(opt_.maxRanks), auth}, id, !auth);
    if (auth) {
      const auto n = makeNonce();
      if (!n) return endConnection(ErrorCode::kInternal, "no random nonce", id);
      nonce_ = *n;
      sendClient(proto::AuthChallenge{nonce_}, id);
    } else {
      authenticated_ = true;
    }
    return;
  }
  if (!authenticated_) {
    const auto* r = std::get_if<proto::AuthResponse>(&m);
    if (!r) return endConnection(ErrorCode::kUnexpectedMessage, "authenticate first", id);
    if (!verifyMac(cfg_.token, nonce_, r->mac)) return endConnection(ErrorCode::kAuthFailed, "authentication failed", id);
    authenticated_ = true;
    log("authenticated");
    sendClient(proto::Ok{}, id);
    return;
  }
  if (std::holds_alternative<proto::CatalogRequest>(m)) {
    sendClient(proto::CatalogReply{listDatasets(opt_.dataDir)}, id);
    return;
  }
  if (const auto* open = std::get_if<proto::SessionOpen>(&m)) {
    if (job_ > 0) return replyError(ErrorCode::kUnexpectedMessage, "a session is already open", id);
    const std::uint32_t ranks = open->rankCount ? open->rankCount : std::uint32_t(std::min(2, opt_.maxRanks));
    if (ranks > std::uint32_t(opt_.maxRanks))
      return replyError(ErrorCode::kLimitExceeded,
                        "ranks " + std::to_string(ranks) + " over --max-ranks " + std::to_string(opt_.maxRanks), id);
    std::string error;
    if (!launch(ranks, error)) return replyError(ErrorCode::kInternal, "cannot start the job: " + error, id);
    forward(m, id);
    return;
  }
  if (job_ < 0) {
    if (std::holds_alternative<proto::StatusRequest>(m)) {
      sendClient(proto::StatusReply{{{"state", "connected"}, {"session", "none"}}}, id);
      return;
    }
    return replyError(ErrorCode::kUnexpectedMessage, "open a session first", id);
  }
  if (const auto* scene = std::get_if<proto::SetScene>(&m); scene && !scene->dataset.empty()) {
    auto resolved = resolveDataset(opt_.dataDir, scene->dataset);
    if (auto* err = std::get_if<proto::ProtocolError>(&resolved)) {
      log("refused dataset '" + scene->dataset + "': " + err->text);
      return replyError(err->code, err->text, id);
    }
    return forward(proto::SetScene{std::get<std::string>(resolved), scene->sceneJson}, id);
  }
  forward(m, id);
}

void Session::onMaster(proto::RelayItem item) {
  if (const auto* refused = std::get_if<proto::RefusedFrame>(&item)) return refuseMasterFrame(*refused);
  const auto& frame = std::get<proto::RelayedFrame>(item);
  if (frame.header.type == proto::Close::kWire.type) return jobEnded("the master closed the session");
  const std::uint32_t id = frame.header.requestId;
  if (refusedRequests_.count(id)) {
    // The client already has its Error for this request.
    if (frame.header.flags & proto::kFlagFinal) refusedRequests_.erase(id);
    return;
  }
  sendClientBytes(frame.bytes);
}

void Session::refuseMasterFrame(const proto::RefusedFrame& refused) {
  const std::uint32_t id = refused.header.requestId;
  const bool final = (refused.header.flags & proto::kFlagFinal) != 0;
  const std::string what = "the rendering job's " + std::string(refused.info->name);
  log("refused " + what + " for request " + std::to_string(id) + ": " + refused.error.text);
  if (refusedRequests_.count(id)) {
    if (final) refusedRequests_.erase(id);
    return;
  }
  // The session goes on: the frame's end was known, the stream is intact.
  replyError(refused.error.code, "pvrd refused " + what + ": " + refused.error.text, id);
  if (!final && id != 0) refusedRequests_.insert(id);
}

bool Session::launch(std::uint32_t ranks, std::string& error) {
  int port = 0;
  listen_ = tcpListen("127.0.0.1", port, error);
  if (listen_ < 0) return false;
  int pipeFds[2];
  if (::pipe2(pipeFds, O_CLOEXEC) != 0) {
    error = errnoText("pipe2");
    return false;
  }
  std::vector<std::string> args{opt_.mpirun, "--oversubscribe", "--bind-to", "none", "-np", std::to_string(ranks)};
  if (!opt_.hostfile.empty()) args.insert(args.end(), {"--hostfile", opt_.hostfile});
  args.insert(args.end(), {cfg_.nodePath, "--server", "--connect", "127.0.0.1:" + std::to_string(port), "--data-dir",
                           opt_.dataDir});
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) {
    error = errnoText("fork");
    ::close(pipeFds[0]);
    ::close(pipeFds[1]);
    return false;
  }
  if (pid == 0) {
    ::signal(SIGTERM, SIG_DFL);
    ::signal(SIGINT, SIG_DFL);
    ::signal(SIGPIPE, SIG_DFL);
    ::signal(SIGCHLD, SIG_DFL);
    ::setpgid(0, 0);
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    const int devnull = ::open("/dev/null", O_RDONLY);
    ::dup2(devnull, 0);
    ::dup2(pipeFds[1], 1);
    ::dup2(pipeFds[1], 2);
    ::close_range(3, ~0u, 0);
    if (::geteuid() == 0) {
      ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
      ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
    }
    ::execvp(argv[0], argv.data());
    const std::string msg = errnoText("exec") + " " + opt_.mpirun + "\n";
    [[maybe_unused]] auto n = ::write(2, msg.data(), msg.size());
    ::_exit(127);
  }
  ::setpgid(pid, pid);
  ::close(pipeFds[1]);
  stderr_ = pipeFds[0];
  ::fcntl(stderr_, F_SETFL, O_NONBLOCK);
  job_ = pid;
  launchedAt_ = monotonicSeconds();
  log("launched mpirun pid " + std::to_string(pid) + " with " + std::to_string(ranks) + " ranks, master port " +
      std::to_string(port));
  return true;
}

void Session::drainStderr() {
  if (stderr_ < 0) return;
  char buf[4096];
  for (;;) {
    const ssize_t n = ::read(stderr_, buf, sizeof buf);
    if (n > 0) {
      stderrTail_.append(buf, std::size_t(n));
      if (stderrTail_.size() > kStderrTail) stderrTail_.erase(0, stderrTail_.size() - kStderrTail);
      continue;
    }
    if (n == 0) {
      ::close(stderr_);
      stderr_ = -1;
    }
    return;
  }
}

void Session::jobEnded(const std::string& why) {
  if (done_) return;
  // Give mpirun a moment to print which rank failed and exit.
  const double until = monotonicSeconds() + 1.0;
  while (monotonicSeconds() < until && !jobExited_) {
    drainStderr();
    if (::waitpid(job_, &jobStatus_, WNOHANG) == job_) jobExited_ = true;
    else ::usleep(20000);
  }
  drainStderr();
  const int rank = rankFromMpirunStderr(stderrTail_);
  std::string tail = stderrTail_.size() > 600 ? stderrTail_.substr(stderrTail_.size() - 600) : stderrTail_;
  const std::string text = rank >= 0 ? "rank " + std::to_string(rank) + " failed: the rendering job ended (" + why + ")"
                                     : "the rendering job ended unexpectedly (" + why + "): " + tail;
  log("job ended: " + text);
  teardown();
  replyError(ErrorCode::kRankFailed, text, 0);
  sendClient(proto::Close{"the rendering job ended"}, 0);
  done_ = true;
}

void Session::teardown() {
  for (int* fd : {&master_, &listen_, &stderr_})
    if (*fd >= 0) ::close(std::exchange(*fd, -1));
  if (job_ <= 0) return;
  const double t0 = monotonicSeconds();
  const std::set<pid_t> family = descendants(job_);
  if (!jobExited_) ::kill(-job_, SIGTERM);
  for (pid_t p : family) ::kill(p, SIGTERM);
  while (!jobExited_ && monotonicSeconds() - t0 < 1.0) {
    if (::waitpid(job_, &jobStatus_, WNOHANG) == job_) jobExited_ = true;
    else ::usleep(10000);
  }
  ::kill(-job_, SIGKILL);
  for (pid_t p : family) ::kill(p, SIGKILL);
  if (!jobExited_) ::waitpid(job_, &jobStatus_, 0);
  jobExited_ = true;
  log("job " + std::to_string(job_) + " gone after " + std::to_string(monotonicSeconds() - t0) + " s");
  job_ = -1;
}

int Session::run() {
  setSendTimeout(client_, opt_.frameTimeout);
  double lastFrame = monotonicSeconds();
  double frameStarted = 0;
  std::vector<std::uint8_t> buf(64 << 10);
  while (!done_ && !gStop) {
    pollfd fds[4];
    int n = 0;
    const int ci = client_ >= 0 ? n : -1;
    if (client_ >= 0) fds[n++] = {client_, POLLIN, 0};
    const int mi = master_ >= 0 ? n : -1;
    if (master_ >= 0) fds[n++] = {master_, POLLIN, 0};
    const int li = listen_ >= 0 && master_ < 0 ? n : -1;
    if (li >= 0) fds[n++] = {listen_, POLLIN, 0};
    const int ei = stderr_ >= 0 ? n : -1;
    if (ei >= 0) fds[n++] = {stderr_, POLLIN, 0};
    if (::poll(fds, nfds_t(n), 100) < 0 && errno != EINTR) {
      log(errnoText("poll"));
      break;
    }
    const double now = monotonicSeconds();
    if (ci >= 0 && (fds[ci].revents & (POLLIN | POLLHUP | POLLERR))) {
      const ssize_t got = ::read(client_, buf.data(), buf.size());
      if (got <= 0) {
        // A frame left unfinished gets its error, in case the client still reads.
        if (const auto& e = fromClient_.endOfStream()) endConnection(e->code, e->text, 0);
        log("client disconnected");
        done_ = true;
        break;
      }
      const std::size_t before = fromClient_.bufferedBytes();
      fromClient_.feed(std::span(buf.data(), std::size_t(got)));
      while (auto frame = fromClient_.pop()) {
        lastFrame = now;
        onClient(std::move(*frame));
        if (done_) break;
      }
      if (done_) break;
      if (const auto& e = fromClient_.error()) {
        log("bad frame from client, first bytes '" + printable(std::span(buf.data(), std::size_t(got))) + "'");
        endConnection(e->code, e->text, 0);
        break;
      }
      if (fromClient_.bufferedBytes() == 0) frameStarted = 0;
      else if (before == 0 || frameStarted == 0) frameStarted = now;
    }
    if (frameStarted > 0 && now - frameStarted > opt_.frameTimeout) {
      endConnection(ErrorCode::kTimeout, "the rest of a started frame did not arrive in time", 0);
      break;
    }
    if (now - lastFrame > opt_.idleTimeout) {
      endConnection(ErrorCode::kTimeout, "idle for " + std::to_string(int(opt_.idleTimeout)) + " s", 0);
      break;
    }
    if (ei >= 0 && (fds[ei].revents & (POLLIN | POLLHUP | POLLERR))) drainStderr();
    if (li >= 0 && (fds[li].revents & POLLIN)) {
      std::string error;
      master_ = tcpAccept(listen_, error);
      if (master_ < 0) {
        jobEnded("master connect: " + error);
        break;
      }
      ::close(std::exchange(listen_, -1));
      log("master connected after " + std::to_string(now - launchedAt_) + " s");
      while (!pendingToMaster_.empty() && master_ >= 0) {
        if (!writeAll(master_, pendingToMaster_.front(), error)) jobEnded("master write failed: " + error);
        pendingToMaster_.pop_front();
      }
      continue;
    }
    if (mi >= 0 && (fds[mi].revents & (POLLIN | POLLHUP | POLLERR))) {
      const ssize_t got = ::read(master_, buf.data(), buf.size());
      if (got <= 0) {
        jobEnded("the master rank's connection closed");
        break;
      }
      fromMaster_.feed(std::span(buf.data(), std::size_t(got)));
      while (auto item = fromMaster_.pop()) {
        onMaster(std::move(*item));
        if (done_) break;
      }
      if (!done_ && fromMaster_.error()) jobEnded("bad frame from the master: " + fromMaster_.error()->text);
    }
    if (job_ > 0 && !done_ && ::waitpid(job_, &jobStatus_, WNOHANG) == job_) {
      jobExited_ = true;
      jobEnded("mpirun exited with status " + std::to_string(WIFEXITED(jobStatus_) ? WEXITSTATUS(jobStatus_) : 128 + WTERMSIG(jobStatus_)));
    }
    if (job_ > 0 && master_ < 0 && listen_ >= 0 && now - launchedAt_ > kMasterConnectSeconds)
      jobEnded("the master rank did not connect within " + std::to_string(int(kMasterConnectSeconds)) + " s");
  }
  if (gStop) {
    log("stopping on signal");
    sendClient(proto::Close{"pvrd is shutting down"}, 0);
  }
  teardown();
  if (client_ >= 0) ::close(client_);
  log("session ended");
  return 0;
}

}  // namespace

int rankFromMpirunStderr(const std::string& text) {
  static const std::regex re(R"(rank\s+(\d+))", std::regex::icase);
  std::smatch m;
  if (std::regex_search(text, m, re)) return std::stoi(m[1].str());
  return -1;
}

int runSession(const SessionConfig& config, int clientFd) {
  struct sigaction sa {};
  sa.sa_handler = onStop;
  ::sigaction(SIGTERM, &sa, nullptr);
  ::sigaction(SIGINT, &sa, nullptr);
  ::signal(SIGPIPE, SIG_IGN);
  ::signal(SIGCHLD, SIG_DFL);
  ::prctl(PR_SET_PDEATHSIG, SIGTERM);
  for (int fd : config.inherited) ::close(fd);
  Session session(config, clientFd);
  return session.run();
}

}  // namespace pvr::daemon
