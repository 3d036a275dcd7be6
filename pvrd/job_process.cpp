#include "job_process.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <map>
#include <set>

#include "sys.h"

namespace pvr::daemon {
namespace {

constexpr std::size_t kTailBytes = 4096;

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

}  // namespace

bool JobProcess::start(const std::vector<std::string>& args, const Environment& environment, int deathSignal,
                       std::string& error) {
  int pipeFds[2];
  if (::pipe2(pipeFds, O_CLOEXEC) != 0) {
    error = errnoText("pipe2");
    return false;
  }
  // The handler has one thread, so the child may still allocate (setenv,
  // the exec error text) between fork and exec.
  std::vector<std::string> argvCopy = args;
  std::vector<char*> argv;
  for (auto& a : argvCopy) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) {
    error = errnoText("fork");
    ::close(pipeFds[0]);
    ::close(pipeFds[1]);
    return false;
  }
  if (pid == 0) {
    for (int sig : {SIGTERM, SIGINT, SIGPIPE, SIGCHLD, SIGHUP}) ::signal(sig, SIG_DFL);
    ::setpgid(0, 0);
    ::prctl(PR_SET_PDEATHSIG, deathSignal);
    const int devnull = ::open("/dev/null", O_RDONLY);
    ::dup2(devnull, 0);
    ::dup2(pipeFds[1], 1);
    ::dup2(pipeFds[1], 2);
    ::close_range(3, ~0u, 0);
    for (const auto& [name, value] : environment) ::setenv(name.c_str(), value.c_str(), 1);
    ::execvp(argv[0], argv.data());
    const std::string msg = errnoText("exec") + " " + args[0] + "\n";
    [[maybe_unused]] auto n = ::write(2, msg.data(), msg.size());
    ::_exit(127);
  }
  ::setpgid(pid, pid);
  ::close(pipeFds[1]);
  output_ = pipeFds[0];
  ::fcntl(output_, F_SETFL, O_NONBLOCK);
  pid_ = pid;
  return true;
}

std::vector<std::string> JobProcess::readLines() {
  std::vector<std::string> lines;
  if (output_ < 0) return lines;
  char buf[4096];
  for (;;) {
    const ssize_t n = ::read(output_, buf, sizeof buf);
    if (n > 0) {
      tail_.append(buf, std::size_t(n));
      if (tail_.size() > kTailBytes) tail_.erase(0, tail_.size() - kTailBytes);
      partial_.append(buf, std::size_t(n));
      for (std::size_t end; (end = partial_.find('\n')) != std::string::npos; partial_.erase(0, end + 1))
        lines.push_back(partial_.substr(0, end));
      continue;
    }
    if (n == 0) {
      ::close(std::exchange(output_, -1));
      if (!partial_.empty()) lines.push_back(std::exchange(partial_, {}));
    }
    return lines;
  }
}

bool JobProcess::reap() {
  if (!exited_ && pid_ > 0 && ::waitpid(pid_, &status_, WNOHANG) == pid_) exited_ = true;
  return exited_;
}

std::string JobProcess::exitText() const {
  if (WIFSIGNALED(status_)) return "killed by signal " + std::to_string(WTERMSIG(status_));
  return "exited with status " + std::to_string(WEXITSTATUS(status_));
}

bool JobProcess::exitedNormally() const { return exited_ && WIFEXITED(status_); }

void JobProcess::closeOutput() {
  if (output_ >= 0) ::close(std::exchange(output_, -1));
}

void JobProcess::stop(double graceSeconds) {
  if (pid_ <= 0) return;
  const double t0 = monotonicSeconds();
  const std::set<pid_t> family = descendants(pid_);
  if (!exited_) ::kill(-pid_, SIGTERM);
  for (pid_t p : family) ::kill(p, SIGTERM);
  while (!reap() && monotonicSeconds() - t0 < graceSeconds) ::usleep(10000);
  ::kill(-pid_, SIGKILL);
  for (pid_t p : family) ::kill(p, SIGKILL);
  if (!exited_ && ::waitpid(pid_, &status_, 0) == pid_) exited_ = true;
  pid_ = -1;
}

}  // namespace pvr::daemon
