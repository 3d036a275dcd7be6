// Each rank's watch thread: Cancel reaching every rank, and the watchdog
// that names a rank which stopped or hung (docs/runtime.md, "Liveness").
//
// Beside the main thread, which may sit for seconds in one frame's ray
// casting or in a message it waits for, a small thread per rank talks on
// the watch channel (comm/watch_channel.h; MPI_THREAD_MULTIPLE):
//   - rank 0's thread sends a cancel notice {request} to every rank when
//     the master cancels a render; each rank's thread raises the stop its
//     ray caster checks between tiles, when the notice names the request
//     the rank works on;
//   - every other rank's thread sends rank 0 a heartbeat each
//     kHeartbeatSeconds: its progress counter (tiles rendered, actions
//     started) and whether it waits on another rank or reads data
//     (comm/liveness.h);
//   - rank 0's thread is the watchdog: a rank whose heartbeats stop (the
//     process is stopped), or whose counter stands still while it neither
//     waits nor is idle (a hang), for longer than the stall limit (longer
//     while it reads data) is reported once through onStall, by number.
// The thread sleeps between polls (kPollSeconds): never a blocking receive
// spinning a core, the cluster's nodes have few of them.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "liveness.h"
#include "watch_channel.h"

namespace pvr::node {

struct WatchOptions {
  double stallSeconds = 30;  // pvr-node --stall-timeout
  // While a rank reads data its limit is this many times longer: a large
  // file on a slow file system legitimately takes minutes.
  double loadingFactor = 4;
};

class RankWatch {
 public:
  static constexpr double kHeartbeatSeconds = 1;
  static constexpr double kPollSeconds = 0.01;

  // Starts the thread. `onStall(rank, seconds)` (rank 0 only) runs on the
  // watch thread, once, for the first rank found stalled.
  RankWatch(comm::WatchChannel& channel, comm::Liveness& liveness, WatchOptions options,
            std::function<void(int rank, double seconds)> onStall = nullptr);
  ~RankWatch();  // stops and joins the thread
  RankWatch(const RankWatch&) = delete;
  RankWatch& operator=(const RankWatch&) = delete;

  // Rank 0, any thread: stop the render of request `id` on every rank.
  void cancel(std::uint32_t id);
  // Main thread, as a request's wave starts: the request this rank works
  // on; the stop is raised at once if it was cancelled already.
  void begin(std::uint32_t request);
  // What the ray caster checks between tiles.
  const std::atomic<bool>& stop() const { return stop_; }

 private:
  using Clock = std::chrono::steady_clock;
  // What rank 0 last heard of a rank.
  struct Seen {
    Clock::time_point heard, advanced;
    std::uint64_t progress = 0;
    bool waiting = false, loading = false;
  };

  void run();
  void markCancelled(std::uint32_t id);
  void heard(int rank, std::uint64_t progress, bool waiting, bool loading, Clock::time_point now);
  // Rank 0: the first rank stalled past its limit, and for how long.
  void checkStalls(Clock::time_point now);

  comm::WatchChannel& channel_;
  comm::Liveness& liveness_;
  WatchOptions options_;
  std::function<void(int, double)> onStall_;
  std::atomic<std::uint32_t> current_{0};    // the request this rank works on
  std::atomic<std::uint32_t> cancelled_{0};  // the last request cancelled
  std::atomic<std::uint32_t> toAnnounce_{0};  // rank 0: a cancel not yet sent to the others
  std::atomic<bool> stop_{false};
  std::atomic<bool> quit_{false};
  std::vector<Seen> seen_;  // rank 0: per rank
  bool reported_ = false;
  std::thread thread_;
};

}  // namespace pvr::node
