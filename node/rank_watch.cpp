#include "rank_watch.h"

#include <cstring>

namespace pvr::node {

namespace {

// Watch messages: one kind byte, then its fields in host order (every
// rank of a job runs the same build).
enum class Kind : std::uint8_t { kCancel = 1, kHeartbeat = 2 };
constexpr std::uint8_t kWaiting = 1, kLoading = 2;

comm::Bytes cancelNotice(std::uint32_t request) {
  comm::Bytes b(1 + 4);
  b[0] = std::byte(Kind::kCancel);
  std::memcpy(b.data() + 1, &request, 4);
  return b;
}

comm::Bytes heartbeat(std::uint64_t progress, bool waiting, bool loading) {
  comm::Bytes b(1 + 8 + 1);
  b[0] = std::byte(Kind::kHeartbeat);
  std::memcpy(b.data() + 1, &progress, 8);
  b[9] = std::byte((waiting ? kWaiting : 0) | (loading ? kLoading : 0));
  return b;
}

}  // namespace

RankWatch::RankWatch(comm::WatchChannel& channel, comm::Liveness& liveness, WatchOptions options,
                     std::function<void(int, double)> onStall)
    : channel_(channel), liveness_(liveness), options_(options), onStall_(std::move(onStall)) {
  const auto now = Clock::now();
  if (channel_.rank() == 0) seen_.assign(std::size_t(channel_.size()), Seen{now, now, 0, true, false});
  thread_ = std::thread([this] { run(); });
}

RankWatch::~RankWatch() {
  quit_ = true;
  if (thread_.joinable()) thread_.join();
}

void RankWatch::cancel(std::uint32_t id) {
  markCancelled(id);
  toAnnounce_ = id;
}

void RankWatch::markCancelled(std::uint32_t id) {
  // Dekker-style with begin(): one of the two sees the other's store
  // (sequentially consistent atomics), so a notice is never lost.
  cancelled_ = id;
  if (current_.load() == id) stop_ = true;
}

void RankWatch::begin(std::uint32_t request) {
  current_ = request;
  stop_ = request != 0 && cancelled_.load() == request;
}

void RankWatch::heard(int rank, std::uint64_t progress, bool waiting, bool loading, Clock::time_point now) {
  Seen& s = seen_[std::size_t(rank)];
  s.heard = now;
  // Waiting on others, or on the client, is no hang of this rank's own.
  if (progress != s.progress || waiting) s.advanced = now;
  s.progress = progress;
  s.waiting = waiting;
  s.loading = loading;
}

void RankWatch::checkStalls(Clock::time_point now) {
  if (reported_ || !onStall_) return;
  for (std::size_t r = 0; r < seen_.size(); ++r) {
    const Seen& s = seen_[r];
    const double limit = options_.stallSeconds * (s.loading ? options_.loadingFactor : 1);
    const double silent = std::chrono::duration<double>(now - s.heard).count();
    const double still = s.waiting ? 0 : std::chrono::duration<double>(now - s.advanced).count();
    const double stalled = std::max(silent, still);
    if (stalled > limit) {
      reported_ = true;
      onStall_(int(r), stalled);
      return;
    }
  }
}

void RankWatch::run() {
  const bool master = channel_.rank() == 0;
  auto nextHeartbeat = Clock::now();
  while (!quit_) {
    const auto now = Clock::now();
    // What the others sent: cancel notices here, heartbeats at rank 0.
    while (auto message = channel_.take()) {
      const auto& [from, bytes] = *message;
      if (bytes.empty()) continue;
      if (Kind(bytes[0]) == Kind::kCancel && bytes.size() == 5) {
        std::uint32_t id = 0;
        std::memcpy(&id, bytes.data() + 1, 4);
        markCancelled(id);
      } else if (Kind(bytes[0]) == Kind::kHeartbeat && bytes.size() == 10 && master) {
        std::uint64_t progress = 0;
        std::memcpy(&progress, bytes.data() + 1, 8);
        const auto flags = std::uint8_t(bytes[9]);
        heard(from, progress, flags & kWaiting, flags & kLoading, now);
      }
    }
    const std::uint64_t progress = liveness_.progress.load();
    const bool waiting = liveness_.waiting.load() > 0, loading = liveness_.loading.load() > 0;
    if (master) {
      if (const std::uint32_t id = toAnnounce_.exchange(0))
        for (int r = 1; r < channel_.size(); ++r) channel_.post(r, cancelNotice(id));
      heard(0, progress, waiting, loading, now);  // rank 0 sees itself directly
      checkStalls(now);
    } else if (now >= nextHeartbeat) {
      channel_.post(0, heartbeat(progress, waiting, loading));
      nextHeartbeat = now + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(kHeartbeatSeconds));
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(kPollSeconds));
  }
}

}  // namespace pvr::node
