#include "brick_cache.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <ctime>

#include "error.h"

namespace pvr::node {

namespace {

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// CPU seconds the calling thread has used.
double threadCpuSeconds() {
  timespec t{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + double(t.tv_nsec) * 1e-9;
}

bool contains(const std::vector<int>& steps, int step) {
  return std::find(steps.begin(), steps.end(), step) != steps.end();
}

}  // namespace

std::shared_ptr<ReadyBrick> makeReady(core::Brick&& brick, int step) {
  auto ready = std::make_shared<ReadyBrick>();
  ready->step = step;
  ready->brick = std::move(brick);
  const auto start = std::chrono::steady_clock::now();
  ready->renderer = std::make_unique<core::BrickRenderer>(ready->brick);
  ready->readSeconds = ready->brick.loadTimes().read;
  ready->preprocessSeconds = ready->brick.loadTimes().preprocess + secondsSince(start);
  return ready;
}

void BrickCache::reset(Reader reader, Prefetcher prefetch) {
  stopReadAhead();
  std::lock_guard lock(mutex_);
  reader_ = std::move(reader);
  prefetch_ = std::move(prefetch);
  classifier_ = {};
  held_.clear();
  recent_.clear();
  wanted_.clear();
  stepBytes_ = 0;
  stats_.bytesHeld = stats_.stepsHeld = 0;
}

void BrickCache::setBudget(std::uint64_t bytes) {
  stopReadAhead();
  std::lock_guard lock(mutex_);
  budget_ = bytes;
  // Least recently used first; a step on screen stays alive with its owner.
  while (stats_.bytesHeld > budget_) evictLocked(recent_.back());
}

void BrickCache::insert(const std::shared_ptr<ReadyBrick>& ready) {
  std::lock_guard lock(mutex_);
  stepBytes_ = ready->bytes();
  if (held_.count(ready->step) || !makeRoom(ready->bytes(), wanted_, true)) return;
  holdLocked(ready);
}

std::shared_ptr<ReadyBrick> BrickCache::take(int step) {
  {
    std::unique_lock lock(mutex_);
    // A step the background thread is reading, or will read next, is worth
    // the wait: it comes no later than a read of our own.
    done_.wait(lock, [&] { return reading_ != step && !contains(queued_, step); });
    if (auto it = held_.find(step); it != held_.end()) {
      ++stats_.hits;
      touchLocked(step);
      return it->second;
    }
    ++stats_.misses;
    if (!reader_) throw pvr::Error(pvr::ErrorCode::kInternal, "brick cache: step " + std::to_string(step) + " has no reader");
  }
  // A miss: read on this thread (the background one may be reading another step).
  announce(step);
  std::shared_ptr<ReadyBrick> ready = makeReady(reader_(step), step);
  std::lock_guard lock(mutex_);
  stepBytes_ = ready->bytes();
  if (!held_.count(step) && makeRoom(ready->bytes(), wanted_, true)) holdLocked(ready);
  return ready;
}

void BrickCache::readAhead(std::vector<int> steps) {
  {
    std::lock_guard lock(mutex_);
    // A budget below one step (known once one was read) holds nothing:
    // the next step is read when shown, from pages asked for now.
    const bool holdsNone = budget_ == 0 || stepBytes_ > budget_;
    if (holdsNone && prefetch_ && !steps.empty() && !held_.count(steps.front())) prefetch_(steps.front());
    // Each step once, in order; the background thread reads those not held.
    wanted_.clear();
    queued_.clear();
    for (int s : steps) {
      if (contains(wanted_, s)) continue;
      wanted_.push_back(s);
      if (!held_.count(s) && s != reading_) queued_.push_back(s);
    }
    if (!reader_ || budget_ == 0) queued_.clear();
    // A running thread takes the new list when its current read ends: the
    // read in progress is not interrupted (it is most likely the next one).
    if (queued_.empty() || active_) return;
    active_ = true;
    stop_ = false;
  }
  if (worker_.joinable()) worker_.join();  // a thread that has finished
  worker_ = std::thread([this] { readAheadLoop(); });
}

void BrickCache::classifyAhead(AheadClassifier classifier) {
  std::lock_guard lock(mutex_);
  classifier_ = std::move(classifier);
}

void BrickCache::readAheadLoop() {
  // Reading ahead fills the time the render leaves idle; where the cores
  // are all rendering it yields to the render threads.
  (void)::setpriority(PRIO_PROCESS, ::gettid(), 10);
  std::unique_lock lock(mutex_);
  while (!stop_ && !queued_.empty()) {
    const int step = queued_.front();
    queued_.erase(queued_.begin());
    if (held_.count(step)) continue;
    // Room at the cost of steps not wanted, or of steps wanted after this
    // one; every step's brick is alike.
    const auto upTo = std::find(wanted_.begin(), wanted_.end(), step);
    const std::vector<int> keep(wanted_.begin(), upTo == wanted_.end() ? upTo : upTo + 1);
    if (stepBytes_ > budget_ || !makeRoom(stepBytes_, keep, false)) break;
    reading_ = step;
    const AheadClassifier classifier = classifier_;
    lock.unlock();
    const auto start = std::chrono::steady_clock::now();
    const double cpuStart = threadCpuSeconds();
    std::shared_ptr<ReadyBrick> ready;
    try {
      announce(step);
      ready = makeReady(reader_(step), step);
      if (classifier.classify) {
        classifier.classify(*ready->renderer);
        ready->classifiedAs = classifier.generation;
      }
    } catch (...) {
      // The step's failure is reported when it is needed and read on demand.
    }
    const double seconds = secondsSince(start), cpuSeconds = threadCpuSeconds() - cpuStart;
    lock.lock();
    stats_.readAheadSeconds += seconds;
    stats_.readAheadCpuSeconds += cpuSeconds;
    if (ready && makeRoom(ready->bytes(), {}, false)) holdLocked(ready);
    reading_ = -1;
    done_.notify_all();
    if (!ready) break;
  }
  queued_.clear();  // what is left is read on demand
  active_ = false;
  done_.notify_all();
}

void BrickCache::announce(int step) const {
  try {
    if (prefetch_) prefetch_(step);
  } catch (...) {
    // A hint: the read reports what is wrong with the step.
  }
}

void BrickCache::stopReadAhead() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  if (worker_.joinable()) worker_.join();
  std::lock_guard lock(mutex_);
  stop_ = false;
}

bool BrickCache::makeRoom(std::uint64_t bytes, const std::vector<int>& keep, bool evictWanted) {
  if (bytes > budget_) return false;
  while (stats_.bytesHeld + bytes > budget_) {
    // The least recently used step nobody else holds, not kept, and not
    // wanted unless evictWanted; wanted ones only after the unwanted.
    int victim = -1;
    for (int pass = 0; pass < (evictWanted ? 2 : 1) && victim < 0; ++pass)
      for (auto it = recent_.rbegin(); it != recent_.rend(); ++it) {
        const bool wanted = contains(wanted_, *it);
        if (held_[*it].use_count() > 1 || contains(keep, *it) || (pass == 0 && wanted)) continue;
        victim = *it;
        break;
      }
    if (victim < 0) return false;
    evictLocked(victim);
  }
  return true;
}

void BrickCache::evictLocked(int step) {
  stats_.bytesHeld -= held_[step]->bytes();
  --stats_.stepsHeld;
  held_.erase(step);
  recent_.remove(step);
}

void BrickCache::holdLocked(const std::shared_ptr<ReadyBrick>& ready) {
  held_[ready->step] = ready;
  recent_.push_front(ready->step);
  stats_.bytesHeld += ready->bytes();
  ++stats_.stepsHeld;
}

void BrickCache::touchLocked(int step) {
  recent_.remove(step);
  recent_.push_front(step);
}

CacheStats BrickCache::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

}  // namespace pvr::node
