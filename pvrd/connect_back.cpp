#include "connect_back.h"

#include <unistd.h>

#include <algorithm>
#include <utility>

#include "sys.h"

namespace pvr::daemon {
namespace {

// A connect-back must complete the handshake and show its JobHello this
// soon (the real master does both right after connecting).
constexpr double kJobHelloSeconds = 5;
// Connections on trial at once; a flood beyond it refuses the oldest, so
// silent connections cannot keep the real master out.
constexpr std::size_t kMaxTrials = 16;

}  // namespace

bool ConnectBack::listen(const std::string& address, std::string& error) {
  int port = 0;
  listen_ = tcpListen(address, port, error);
  if (listen_ < 0) return false;
  where_ = address + ":" + std::to_string(port);
  return true;
}

std::vector<pollfd> ConnectBack::pollFds() const {
  std::vector<pollfd> fds;
  if (listen_ >= 0) fds.push_back({listen_, POLLIN, 0});
  for (const Trial& t : trials_) fds.push_back({t.fd, POLLIN, 0});
  return fds;
}

void ConnectBack::refuse(Trial& trial, const std::string& reason) {
  logEvent(session_, "refused a connect-back from " + trial.peer + ": " + reason + "; first bytes '" +
                         trial.check.firstBytes() + "'");
  ::close(std::exchange(trial.fd, -1));
}

std::optional<ConnectBack::Master> ConnectBack::serve(std::span<const pollfd> polled, double now) {
  if (listen_ < 0) return std::nullopt;
  std::optional<Master> master;
  // The trials polled (the ones accepted below come after them).
  const std::size_t polledTrials = std::min(trials_.size(), polled.empty() ? 0 : polled.size() - 1);
  for (std::size_t i = 0; i < polledTrials && !master; ++i) {
    Trial& t = trials_[i];
    if (!(polled[i + 1].revents & (POLLIN | POLLHUP | POLLERR))) continue;
    std::uint8_t buf[4096];
    const ssize_t got = ::read(t.fd, buf, sizeof buf);
    if (got <= 0) {
      refuse(t, "closed before its JobHello");
      continue;
    }
    const auto failure = t.channel->receive(std::span(buf, std::size_t(got)));
    std::string error;
    // Handshake replies, or the alert that says why we stop: a few hundred
    // bytes into a fresh socket's buffer.
    if (!writeAll(t.fd, t.channel->takeOutgoing(), error)) {
      refuse(t, "write failed: " + error);
      continue;
    }
    if (failure) {
      refuse(t, failure->text);
      continue;
    }
    auto result = t.check.feed(t.channel->takeIncoming());
    if (auto* refused = std::get_if<JobHelloCheck::Refused>(&result)) {
      refuse(t, refused->reason);
    } else if (auto* accepted = std::get_if<JobHelloCheck::Accepted>(&result)) {
      master = Master{std::exchange(t.fd, -1), t.peer, std::move(t.channel), std::move(accepted->rest)};
    }
  }
  for (Trial& t : trials_)
    if (t.fd >= 0 && now > t.deadline) refuse(t, "no JobHello within " + std::to_string(int(kJobHelloSeconds)) + " s");
  std::erase_if(trials_, [](const Trial& t) { return t.fd < 0; });
  if (master) {
    for (Trial& t : trials_) refuse(t, "the master connected first");
    close();
    return master;
  }
  if (!polled.empty() && (polled[0].revents & POLLIN)) {
    std::string error;
    const int fd = tcpAccept(listen_, error);
    if (fd < 0) {
      logEvent(session_, "connect-back accept: " + error);
    } else {
      if (trials_.size() >= kMaxTrials) {
        refuse(trials_.front(), "too many connect-backs on trial");
        trials_.erase(trials_.begin());
      }
      trials_.push_back({fd, peerName(fd),
                         std::make_unique<proto::SecureChannel>(proto::SecureChannel::Role::kServer, secret_,
                                                                proto::kConnectBackPurpose),
                         JobHelloCheck(secret_), now + kJobHelloSeconds});
    }
  }
  return std::nullopt;
}

void ConnectBack::close() {
  for (Trial& t : trials_)
    if (t.fd >= 0) ::close(t.fd);
  trials_.clear();
  if (listen_ >= 0) ::close(std::exchange(listen_, -1));
}

}  // namespace pvr::daemon
