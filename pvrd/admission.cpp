#include "admission.h"

#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>

namespace pvr::daemon {
namespace {

// How long a handler waits for the daemon's answer to a slot request: the
// daemon answers from its poll loop at once; only a daemon being stopped
// does not.
constexpr int kSlotAnswerMillis = 5000;

void sendByte(int fd, char c) {
  if (fd >= 0) [[maybe_unused]] auto n = ::send(fd, &c, 1, MSG_NOSIGNAL);
}

std::string tooManySessions(int maxSessions) {
  return "too many sessions: all " + std::to_string(maxSessions) +
         " of --max-sessions are open; try again when one ends";
}

}  // namespace

std::optional<std::string> Admission::refusalAtAccept() const {
  if (handshakes() >= limits_.handshakes)
    return "too many connections in handshake (" + std::to_string(handshakes()) + " of --max-unauthenticated " +
           std::to_string(limits_.handshakes) + "); try again shortly";
  if (connections() >= std::size_t(limits_.connections))
    return "too many connections (" + std::to_string(connections()) + " of --max-connections " +
           std::to_string(limits_.connections) + ")";
  return std::nullopt;
}

void Admission::add(pid_t handler) { stages_[handler] = Stage::kHandshake; }

void Admission::authenticated(pid_t handler) {
  if (auto it = stages_.find(handler); it != stages_.end() && it->second == Stage::kHandshake)
    it->second = Stage::kConnected;
}

std::optional<std::string> Admission::requestSlot(pid_t handler) {
  const auto it = stages_.find(handler);
  if (it == stages_.end() || it->second == Stage::kHandshake) return "authenticate first";
  if (it->second == Stage::kSession) return std::nullopt;
  if (sessions() >= limits_.sessions) return tooManySessions(limits_.sessions);
  it->second = Stage::kSession;
  return std::nullopt;
}

void Admission::releaseSlot(pid_t handler) {
  if (auto it = stages_.find(handler); it != stages_.end() && it->second == Stage::kSession)
    it->second = Stage::kConnected;
}

void Admission::remove(pid_t handler) { stages_.erase(handler); }

int Admission::count(Stage stage) const {
  return int(std::count_if(stages_.begin(), stages_.end(), [&](const auto& e) { return e.second == stage; }));
}

void AdmissionLink::authenticated() const { sendByte(fd_, admission_wire::kAuthenticated); }

void AdmissionLink::releaseSlot() const { sendByte(fd_, admission_wire::kReleaseSlot); }

std::optional<std::string> AdmissionLink::requestSlot(int maxSessions) const {
  // Without a daemon (a handler run alone) there is no ledger to ask.
  if (fd_ < 0) return std::nullopt;
  sendByte(fd_, admission_wire::kRequestSlot);
  pollfd p{fd_, POLLIN, 0};
  char answer = 0;
  if (::poll(&p, 1, kSlotAnswerMillis) != 1 || ::recv(fd_, &answer, 1, 0) != 1)
    return "pvrd did not answer the request for a session slot";
  if (answer == admission_wire::kGranted) return std::nullopt;
  return tooManySessions(maxSessions);
}

}  // namespace pvr::daemon
