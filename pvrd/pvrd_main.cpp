// pvrd: accepts connections and forks one session handler per client
// (session.h). The loop polls the listening socket and a self-pipe that the
// SIGCHLD, SIGTERM and SIGINT handlers write to.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <climits>
#include <cstdio>
#include <map>

#include "advertise.h"
#include "auth.h"
#include "token_file.h"
#include "options.h"
#include "pvr_protocol.h"
#include "session.h"
#include "sys.h"

using namespace pvr::daemon;

namespace {

int gSignalPipe[2] = {-1, -1};

void onSignal(int sig) {
  const int saved = errno;
  const char c = char(sig);
  [[maybe_unused]] auto n = ::write(gSignalPipe[1], &c, 1);
  errno = saved;
}

std::string nodeNextToSelf() {
  char buf[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return "pvr-node";
  std::string self(buf, std::size_t(n));
  return self.substr(0, self.rfind('/') + 1) + "pvr-node";
}

void refuse(int fd, pvr::proto::ErrorCode code, const std::string& text) {
  std::string error;
  setSendTimeout(fd, 1);
  writeAll(fd, pvr::proto::encode(pvr::proto::ErrorMessage{code, text}, 0, pvr::proto::kFlagFinal), error);
  writeAll(fd, pvr::proto::encode(pvr::proto::Close{text}, 0, pvr::proto::kFlagFinal), error);
  ::close(fd);
}

}  // namespace

int main(int argc, char** argv) {
  std::string error;
  const auto options = parseOptions(std::vector<std::string>(argv + 1, argv + argc), error);
  if (!options) {
    std::fprintf(stderr, "pvrd: %s\nusage: %s\n", error.c_str(), kUsage);
    return 2;
  }
  SessionConfig config;
  config.options = &*options;
  config.nodePath = options->node.empty() ? nodeNextToSelf() : options->node;
  config.daemonPid = ::getpid();
  config.advertise = advertiseAddress(*options, error);
  if (config.advertise.empty()) {
    std::fprintf(stderr, "pvrd: %s\n", error.c_str());
    return 2;
  }
  if (!options->tokenFile.empty()) {
    const auto token = pvr::proto::readTokenFile(options->tokenFile);
    if (const auto* refused = std::get_if<pvr::proto::TokenFileError>(&token)) {
      std::fprintf(stderr, "pvrd: %s\n", refused->text.c_str());
      return 2;
    }
    config.token = std::get<std::string>(token);
  }
  if (::pipe2(gSignalPipe, O_CLOEXEC | O_NONBLOCK) != 0) {
    std::fprintf(stderr, "pvrd: %s\n", errnoText("pipe2").c_str());
    return 1;
  }
  struct sigaction sa {};
  sa.sa_handler = onSignal;
  sa.sa_flags = SA_RESTART;
  for (int sig : {SIGCHLD, SIGTERM, SIGINT}) ::sigaction(sig, &sa, nullptr);
  ::signal(SIGPIPE, SIG_IGN);

  int port = options->port;
  const int listenFd = tcpListen(options->host, port, error);
  if (listenFd < 0) {
    std::fprintf(stderr, "pvrd: cannot listen on %s:%d: %s\n", options->host.c_str(), options->port, error.c_str());
    return 1;
  }
  std::printf("pvrd listening on %s:%d\n", options->host.c_str(), port);
  std::fflush(stdout);
  logEvent(0, "listening on " + options->host + ":" + std::to_string(port) + ", data " + options->dataDir + ", node " +
                  config.nodePath + ", launcher " + options->launcher + ", ranks connect back to " + config.advertise +
                  (config.token.empty() ? "" : ", token required"));
  if (options->launcher != "mpirun" && options->advertise.empty() && isLoopback(config.advertise))
    logEvent(0, "warning: ranks on other hosts cannot reach " + config.advertise + "; give --advertise ADDR");

  std::map<pid_t, std::uint64_t> handlers;
  std::uint64_t nextSession = 1;
  bool stopping = false;
  while (!stopping) {
    pollfd fds[2] = {{listenFd, POLLIN, 0}, {gSignalPipe[0], POLLIN, 0}};
    if (::poll(fds, 2, -1) < 0 && errno != EINTR) {
      logEvent(0, errnoText("poll"));
      break;
    }
    if (fds[1].revents & POLLIN) {
      char sigs[64];
      ssize_t n;
      while ((n = ::read(gSignalPipe[0], sigs, sizeof sigs)) > 0)
        for (ssize_t i = 0; i < n; ++i)
          if (sigs[i] == SIGTERM || sigs[i] == SIGINT) stopping = true;
      int status = 0;
      pid_t pid;
      while ((pid = ::waitpid(-1, &status, WNOHANG)) > 0) {
        if (auto it = handlers.find(pid); it != handlers.end()) {
          logEvent(it->second, "handler " + std::to_string(pid) + " exited");
          handlers.erase(it);
        }
      }
    }
    if (stopping || !(fds[0].revents & POLLIN)) continue;
    const int client = tcpAccept(listenFd, error);
    if (client < 0) {
      logEvent(0, error);
      continue;
    }
    const std::uint64_t id = nextSession++;
    if (handlers.size() >= std::size_t(options->maxSessions)) {
      logEvent(id, "refused: too many sessions (" + std::to_string(handlers.size()) + ")");
      refuse(client, pvr::proto::ErrorCode::kLimitExceeded, "too many sessions");
      continue;
    }
    const pid_t pid = ::fork();
    if (pid < 0) {
      logEvent(id, errnoText("fork"));
      refuse(client, pvr::proto::ErrorCode::kInternal, "cannot fork a session handler");
      continue;
    }
    if (pid == 0) {
      config.id = id;
      config.inherited = {listenFd, gSignalPipe[0], gSignalPipe[1]};
      ::_exit(runSession(config, client));
    }
    ::close(client);
    handlers[pid] = id;
    logEvent(id, "accepted; handler pid " + std::to_string(pid));
  }
  logEvent(0, "stopping: ending " + std::to_string(handlers.size()) + " session(s)");
  ::close(listenFd);
  for (auto& [pid, id] : handlers) ::kill(pid, SIGTERM);
  const double t0 = monotonicSeconds();
  while (!handlers.empty()) {
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, WNOHANG);
    if (pid > 0) {
      handlers.erase(pid);
      continue;
    }
    if (pid < 0 && errno == ECHILD) break;
    if (monotonicSeconds() - t0 > 5) {
      for (auto& [p, id] : handlers) ::kill(p, SIGKILL);
    }
    ::usleep(10000);
  }
  logEvent(0, "stopped");
  return 0;
}
