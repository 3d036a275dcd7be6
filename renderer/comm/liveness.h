// What a rank's main thread shows its watch thread (node/rank_watch.h):
// a counter it advances as work gets done (tiles rendered, steps read),
// and whether it is waiting on another rank or on the client, when no
// progress is expected of it. A rank whose counter stands still while it
// is not waiting is hung; one that waits is at most held up by another.
// Atomics only: the main thread writes, the watch thread reads.
#pragma once

#include <atomic>
#include <cstdint>

namespace pvr::comm {

struct Liveness {
  std::atomic<std::uint64_t> progress{0};
  std::atomic<int> waiting{0};  // > 0 while blocked on a message or the client
  std::atomic<int> loading{0};  // > 0 while reading data: a longer stall limit applies
};

// Marks `liveness` (if any) as waiting, or loading, for the scope's life.
// Nested scopes count.
class LivenessScope {
 public:
  enum class Kind { kWaiting, kLoading };
  LivenessScope(Liveness* liveness, Kind kind) : counter_(liveness ? &select(*liveness, kind) : nullptr) {
    if (counter_) counter_->fetch_add(1);
  }
  ~LivenessScope() {
    if (counter_) counter_->fetch_sub(1);
  }
  LivenessScope(const LivenessScope&) = delete;
  LivenessScope& operator=(const LivenessScope&) = delete;

 private:
  static std::atomic<int>& select(Liveness& l, Kind kind) { return kind == Kind::kWaiting ? l.waiting : l.loading; }
  std::atomic<int>* counter_;
};

}  // namespace pvr::comm
