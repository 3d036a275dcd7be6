// The communicator a compositing strategy talks to; it never sees MPI.
//
// Point-to-point messages are byte buffers with a tag. Two ranks that swap
// must use sendReceive (or exchange), never send-then-receive on both sides:
// an MPI send of a large buffer may block until the partner receives, and
// two such sends deadlock. Collectives (broadcast, allGather, allReduce*,
// agree) must be called by every rank in the same order.
//
// Errors: an exception never crosses a collective. Each rank runs a phase,
// catches what it throws, and calls agree() with its outcome; every rank
// learns the failure of the lowest world rank and throws the same
// FailureError (runAgreed does all of this). A failure carries the world
// rank that raised it as data, so it keeps its origin while it travels
// through sub-communicators and further agreements. The implementations:
// InProcessCommunicator (threads of one process, for tests),
// MpiCommunicator (mpi_communicator.cpp, the one file that includes mpi.h)
// and SubCommunicator (a cluster of another communicator's ranks).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "error.h"

namespace pvr::comm {

using Bytes = std::vector<std::byte>;

// Tags below kFirstReservedTag are free for strategies and programs;
// collectives built on point-to-point messages use the tags above it.
constexpr int kFirstReservedTag = 30000;

struct Outgoing {
  int to = 0;
  std::span<const std::byte> data;
};

// One rank's failure as every rank learns it.
struct Failure {
  int origin = 0;  // the world rank that raised it
  ErrorCode code = ErrorCode::kInternal;
  std::string message;
  // "rank 3: volume.raw: truncated" — the text every rank throws.
  std::string describe() const;
};

// What runAgreed throws on every rank: the agreed failure, origin included.
class FailureError : public Error {
 public:
  explicit FailureError(Failure f) : Error(f.code, f.describe()), failure_(std::move(f)) {}
  const Failure& failure() const { return failure_; }

 private:
  Failure failure_;
};

class Communicator {
 public:
  virtual ~Communicator() = default;

  virtual int rank() const = 0;
  virtual int size() const = 0;
  // This rank's rank in the whole job: what a failure names.
  virtual int worldRank() const { return rank(); }

  // Sends `data` to rank `to`. May block until it is received.
  virtual void send(int to, int tag, std::span<const std::byte> data) = 0;
  // Receives the next message from `from` with `tag` (messages between one
  // pair with one tag arrive in the order sent).
  virtual Bytes receive(int from, int tag) = 0;
  // Sends to `to` and receives from `from` at once: safe when two ranks swap.
  virtual Bytes sendReceive(int to, std::span<const std::byte> data, int from, int tag) = 0;
  // Starts every send, receives one message from each of `from` (in that
  // order), then waits for the sends: safe for any pattern of groups.
  virtual std::vector<Bytes> exchange(std::span<const Outgoing> sends, std::span<const int> from,
                                      int tag) = 0;

  // Collectives. The defaults use point-to-point messages through rank 0
  // on reserved tags; MpiCommunicator overrides them with MPI's own.
  virtual void broadcast(Bytes& data, int root);
  virtual std::vector<Bytes> allGather(std::span<const std::byte> mine);
  virtual void allReduceSum(std::span<std::uint64_t> values);
  virtual void allReduceMax(std::span<double> values);
  virtual void barrier();

  // Every rank passes its outcome of a phase (nullopt: it went well); every
  // rank returns the failure of the lowest origin rank, or nullopt.
  std::optional<Failure> agree(const std::optional<Failure>& mine);
};

// The failure a caught exception describes: a FailureError keeps its
// origin; anything else is attributed to `worldRank`.
Failure failureOf(std::exception_ptr error, int worldRank);

// A failure or its absence as bytes, for messages that carry one (an image
// or the failure that replaced it); agree() uses the same form.
Bytes encodeFailure(const std::optional<Failure>& failure);
std::optional<Failure> decodeFailure(std::span<const std::byte> bytes);

// Runs `phase` on this rank, then agrees with every other rank: if any rank
// threw, every rank throws FailureError with the agreed failure.
// A collective phase (all ranks take part) must not throw on some ranks
// only, so `phase` should hold the local work between two agreements.
void runAgreed(Communicator& comm, const std::function<void()>& phase);

}  // namespace pvr::comm
