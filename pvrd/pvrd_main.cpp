// pvrd: accepts connections and forks one session handler per client
// (session.h). The loop polls the listening socket, a self-pipe that the
// SIGCHLD, SIGTERM and SIGINT handlers write to, and each handler's
// socketpair, on which it reports its stage and asks for a session slot
// (admission.h).
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <climits>
#include <cstdio>
#include <map>
#include <vector>

#include "admission.h"
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

// A running handler: its session number and the daemon's end of its link.
struct Handler {
  std::uint64_t id = 0;
  int link = -1;
};

// One event from a handler's link; a slot request is answered at once.
void serveHandlerLink(pid_t pid, Handler& handler, Admission& admission) {
  char events[16];
  const ssize_t n = ::recv(handler.link, events, sizeof events, MSG_DONTWAIT);
  if (n == 0) {
    // The handler exited (its SIGCHLD reaps it): it holds nothing now.
    admission.remove(pid);
    ::close(std::exchange(handler.link, -1));
    return;
  }
  for (ssize_t i = 0; i < n; ++i) {
    switch (events[i]) {
      case admission_wire::kAuthenticated: admission.authenticated(pid); break;
      case admission_wire::kReleaseSlot: admission.releaseSlot(pid); break;
      case admission_wire::kRequestSlot: {
        const auto refused = admission.requestSlot(pid);
        if (refused) logEvent(handler.id, "no session slot: " + *refused);
        const char answer = refused ? admission_wire::kRefused : admission_wire::kGranted;
        [[maybe_unused]] auto sent = ::send(handler.link, &answer, 1, MSG_NOSIGNAL);
        break;
      }
      default: logEvent(handler.id, "handler link: unknown event, ignored");
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string error;
  const auto options = parseOptions(std::vector<std::string>(argv + 1, argv + argc), error);
  if (!options) {
    const std::string usage(kUsage);
    std::fprintf(stderr, "pvrd: %s\n%s(pvrd --help lists every option)\n", error.c_str(),
                 usage.substr(0, usage.find('\n') + 1).c_str());
    return 2;
  }
  if (options->help) {
    std::fputs(kUsage, stdout);
    return 0;
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

  std::map<pid_t, Handler> handlers;
  Admission admission({options->maxUnauthenticated, options->maxConnections, options->maxSessions});
  std::uint64_t nextSession = 1;
  bool stopping = false;
  std::vector<pollfd> fds;
  std::vector<pid_t> polledHandlers;
  while (!stopping) {
    fds = {{listenFd, POLLIN, 0}, {gSignalPipe[0], POLLIN, 0}};
    polledHandlers.clear();
    for (const auto& [pid, handler] : handlers)
      if (handler.link >= 0) {
        fds.push_back({handler.link, POLLIN, 0});
        polledHandlers.push_back(pid);
      }
    if (::poll(fds.data(), nfds_t(fds.size()), -1) < 0 && errno != EINTR) {
      logEvent(0, errnoText("poll"));
      break;
    }
    for (std::size_t i = 0; i < polledHandlers.size(); ++i)
      if (fds[2 + i].revents & (POLLIN | POLLHUP | POLLERR))
        if (auto it = handlers.find(polledHandlers[i]); it != handlers.end() && it->second.link >= 0)
          serveHandlerLink(it->first, it->second, admission);
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
          logEvent(it->second.id, "handler " + std::to_string(pid) + " exited");
          if (it->second.link >= 0) ::close(it->second.link);
          handlers.erase(it);
        }
        admission.remove(pid);
      }
    }
    if (stopping || !(fds[0].revents & POLLIN)) continue;
    const int client = tcpAccept(listenFd, error);
    if (client < 0) {
      logEvent(0, error);
      continue;
    }
    const std::uint64_t id = nextSession++;
    if (const auto refused = admission.refusalAtAccept()) {
      logEvent(id, "refused: " + *refused);
      refuse(client, pvr::proto::ErrorCode::kLimitExceeded, *refused);
      continue;
    }
    int link[2];
    if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, link) != 0) {
      logEvent(id, errnoText("socketpair"));
      refuse(client, pvr::proto::ErrorCode::kInternal, "cannot start a session handler");
      continue;
    }
    const pid_t pid = ::fork();
    if (pid < 0) {
      logEvent(id, errnoText("fork"));
      ::close(link[0]);
      ::close(link[1]);
      refuse(client, pvr::proto::ErrorCode::kInternal, "cannot fork a session handler");
      continue;
    }
    if (pid == 0) {
      config.id = id;
      config.admission = link[1];
      config.inherited = {listenFd, gSignalPipe[0], gSignalPipe[1], link[0]};
      for (const auto& [other, handler] : handlers)
        if (handler.link >= 0) config.inherited.push_back(handler.link);
      ::_exit(runSession(config, client));
    }
    ::close(client);
    ::close(link[1]);
    handlers[pid] = {id, link[0]};
    admission.add(pid);
    logEvent(id, "accepted; handler pid " + std::to_string(pid));
  }
  logEvent(0, "stopping: ending " + std::to_string(handlers.size()) + " session(s)");
  ::close(listenFd);
  for (auto& [pid, handler] : handlers) ::kill(pid, SIGTERM);
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
      for (auto& [p, handler] : handlers) ::kill(p, SIGKILL);
    }
    ::usleep(10000);
  }
  logEvent(0, "stopped");
  return 0;
}
