// Failures that remember the world rank that raised them.
//
// composite::runAgreed names a failure by its rank in the communicator it
// ran on; on a cluster that is not the world rank. Runtime actions throw
// RankError instead when the failure travelled from another rank, and
// agreeWorld/agreeOn keep the origin, so the client reads "rank 5: ..."
// for the rank that actually failed.
#pragma once

#include <exception>
#include <functional>
#include <optional>
#include <string>

#include "communicator.h"
#include "error.h"

namespace pvr::runtime {

struct RankFailure {
  int origin = 0;  // world rank that raised it
  ErrorCode code = ErrorCode::kInternal;
  std::string message;
  std::string describe() const { return "rank " + std::to_string(origin) + ": " + message; }
};

// A failure raised on world rank `origin`, possibly elsewhere.
class RankError : public Error {
 public:
  explicit RankError(const RankFailure& f) : Error(f.code, f.describe()), failure_(f) {}
  const RankFailure& failure() const { return failure_; }

 private:
  RankFailure failure_;
};

// The failure an exception describes; `worldRank` unless it is a RankError.
RankFailure failureOf(std::exception_ptr error, int worldRank);

composite::Bytes encodeFailure(const std::optional<RankFailure>& failure);
std::optional<RankFailure> decodeFailure(std::span<const std::byte> bytes);

// Collective on `comm`: every rank passes its outcome and gets the failure
// of the lowest origin rank, or nullopt.
std::optional<RankFailure> agreeOn(composite::Communicator& comm, const std::optional<RankFailure>& mine);

// Runs `phase`, then agrees on `comm`; throws RankError on every rank if
// any failed. `worldRank` is this rank's world rank.
void runAgreedOn(composite::Communicator& comm, int worldRank, const std::function<void()>& phase);

}  // namespace pvr::runtime
