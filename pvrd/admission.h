// Who may hold what in pvrd: the daemon's ledger of its connections.
//
// A connection passes three stages: handshake (accepted, not yet
// authenticated: Hello, and with a token the secure channel's handshake),
// connected (authenticated, no job), session (a job runs for it). Strangers
// are kept small and short-lived: connections in handshake have their own
// limit (--max-unauthenticated), so a flood of them never keeps a real
// client out, and a handshake timeout (session.cpp) ends them. A session
// slot (--max-sessions) is taken at SessionOpen, not at accept: a client
// that only lists datasets or polls status holds no slot. --max-connections
// bounds the handler processes in all.
//
// Each handler tells the daemon of its stage over a socketpair
// (AdmissionLink below); the daemon answers a slot request at once.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <map>
#include <optional>
#include <string>

namespace pvr::daemon {

struct AdmissionLimits {
  int handshakes = 8;    // connections not yet authenticated
  int connections = 64;  // handler processes in all
  int sessions = 4;      // connections with a job
};

class Admission {
 public:
  explicit Admission(AdmissionLimits limits) : limits_(limits) {}

  // At accept: why the connection must be turned away, or nullopt (then
  // add() it once its handler runs).
  std::optional<std::string> refusalAtAccept() const;
  void add(pid_t handler);
  // The handler's connection authenticated.
  void authenticated(pid_t handler);
  // The handler asks for a session slot: granted, or why not.
  std::optional<std::string> requestSlot(pid_t handler);
  // The handler's job ended and it serves on without one.
  void releaseSlot(pid_t handler);
  // The handler exited: whatever it held is free.
  void remove(pid_t handler);

  int handshakes() const { return count(Stage::kHandshake); }
  int sessions() const { return count(Stage::kSession); }
  std::size_t connections() const { return stages_.size(); }

 private:
  enum class Stage { kHandshake, kConnected, kSession };
  int count(Stage stage) const;

  AdmissionLimits limits_;
  std::map<pid_t, Stage> stages_;
};

// The handler's end of its socketpair with the daemon: one byte per event,
// and a one-byte answer to a slot request.
namespace admission_wire {
inline constexpr char kAuthenticated = 'a';
inline constexpr char kRequestSlot = 's';
inline constexpr char kReleaseSlot = 'r';
inline constexpr char kGranted = 'y';
inline constexpr char kRefused = 'n';
}  // namespace admission_wire

class AdmissionLink {
 public:
  explicit AdmissionLink(int fd = -1) : fd_(fd) {}
  void authenticated() const;
  // Blocks until the daemon answers (it does at once; at most a few
  // seconds). Why not, or nullopt when the slot is ours.
  std::optional<std::string> requestSlot(int maxSessions) const;
  void releaseSlot() const;

 private:
  int fd_;
};

}  // namespace pvr::daemon
