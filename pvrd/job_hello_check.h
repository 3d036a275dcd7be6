// The gate on a connect-back connection: the session handler listens on the
// advertised address, where anyone may connect, so a connection counts as
// the master rank only once its first frame is a JobHello carrying the
// session's one-time secret (docs/pvrd.md, "The job's secret"). Sans-IO:
// feed it the bytes that arrive.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <variant>
#include <vector>

namespace pvr::daemon {

class JobHelloCheck {
 public:
  explicit JobHelloCheck(std::string secret) : secret_(std::move(secret)) {}

  struct Waiting {};
  // The secret is right; `rest` holds the bytes after the JobHello, the
  // master's first frames.
  struct Accepted {
    std::vector<std::uint8_t> rest;
  };
  // Not the job: why, for the log.
  struct Refused {
    std::string reason;
  };
  using Result = std::variant<Waiting, Accepted, Refused>;

  // Takes the next bytes of the connection. A first frame of any other
  // type is refused as soon as its header is in, before its payload.
  Result feed(std::span<const std::uint8_t> bytes);

  // The first bytes received, non-printable ones masked, for the log.
  std::string firstBytes() const;

 private:
  std::string secret_;
  std::vector<std::uint8_t> received_;
};

}  // namespace pvr::daemon
