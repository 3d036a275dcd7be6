// Small messages beside the work, for each rank's watch thread
// (node/rank_watch.h): rank 0's cancel notices to every rank, and every
// rank's heartbeats to rank 0. They travel on a message space of their
// own, so they never match the messages and collectives of the work, and
// the channel is called from the watch thread while the rank's main
// thread runs its own communication (MPI_THREAD_MULTIPLE). No call blocks:
// sends are queued (a stopped peer never holds up the sender), and take()
// returns only what has arrived.
#pragma once

#include <optional>
#include <span>
#include <utility>

#include "communicator.h"

namespace pvr::comm {

class WatchChannel {
 public:
  virtual ~WatchChannel() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  // Sends `message` (a few bytes) to rank `to` without waiting for it.
  virtual void post(int to, std::span<const std::byte> message) = 0;
  // The next message that has arrived from any rank: {sender, bytes}.
  virtual std::optional<std::pair<int, Bytes>> take() = 0;
};

}  // namespace pvr::comm
