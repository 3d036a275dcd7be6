// Where a session's master rank connects back: a socket listening on the
// advertised address (any port) and the connections that have yet to prove
// that they are the job this session launched: first the secure channel's
// handshake keyed by the session's secret (only a holder of the secret
// completes it), then, inside it, a JobHello with the secret
// (job_hello_check.h). Refused ones are logged in one line and closed; the
// listening goes on until one proves itself.
#pragma once

#include <poll.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "job_hello_check.h"
#include "secure_channel.h"

namespace pvr::daemon {

class ConnectBack {
 public:
  ConnectBack(std::uint64_t session, std::string secret) : session_(session), secret_(std::move(secret)) {}
  ConnectBack(const ConnectBack&) = delete;
  ConnectBack& operator=(const ConnectBack&) = delete;
  ~ConnectBack() { close(); }

  // Listens on `address`, port 0 (numeric IPv4). False, with error text,
  // when it cannot.
  bool listen(const std::string& address, std::string& error);
  // "ADDR:PORT" to pass to the master as --connect.
  const std::string& where() const { return where_; }

  // The descriptors to poll for input: the listening socket, then the
  // connections on trial.
  std::vector<pollfd> pollFds() const;

  // The master's proven connection, its channel (every later byte goes
  // through it) and the plaintext that followed its JobHello.
  struct Master {
    int fd = -1;
    std::string peer;
    std::unique_ptr<proto::SecureChannel> channel;
    std::vector<std::uint8_t> rest;
  };
  // Serves what poll() reported for pollFds() (same order): accepts, reads,
  // refuses connections that fail the check or stay silent too long.
  // Returns the master once one is accepted; the others are closed then.
  std::optional<Master> serve(std::span<const pollfd> polled, double now);

  // Closes the listening socket and every connection on trial.
  void close();

 private:
  struct Trial {
    int fd;
    std::string peer;
    std::unique_ptr<proto::SecureChannel> channel;
    JobHelloCheck check;
    double deadline;
  };
  void refuse(Trial& trial, const std::string& reason);

  std::uint64_t session_;
  std::string secret_;
  int listen_ = -1;
  std::string where_;
  std::vector<Trial> trials_;
};

}  // namespace pvr::daemon
