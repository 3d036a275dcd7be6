// The caching cluster of paper 003 (section 7) on the render ranks: each
// rank keeps the bricks of time steps it showed or will show, read and
// preprocessed (value range, macrocell grid) so that a step is ready to
// classify and render. While the current step renders, a background thread
// reads the upcoming steps' bricks, within a per-rank memory budget
// (RuntimeSettings::cacheMegabytes). What does not fit is read on demand.
//
// Eviction: a step the current request will not show again goes first
// (least recently used among those), then the least recently used of the
// others; the brick on screen is never evicted (its owner holds it).
// Read-ahead never evicts a step it still needs to make room for a later
// one: it stops there.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "brick.h"
#include "raycast/raycaster.h"
#include "scene_bricks.h"

namespace pvr::node {

// One step's brick for this rank, with its renderer (macrocells built).
// Held by pointer: the renderer refers to `brick`, so it never moves.
// A scene of several volumes puts its bricks on screen as `scene`
// instead (scene_bricks.h; never cached: brick and renderer stay empty).
struct ReadyBrick {
  int step = 0;
  core::Brick brick;
  std::unique_ptr<core::BrickRenderer> renderer;
  std::shared_ptr<SceneBricks> scene;
  double readSeconds = 0;        // I/O (brick.loadTimes().read)
  double preprocessSeconds = 0;  // fused preprocessing in the reader plus the renderer's build
  // The classification the renderer holds (AheadClassifier::generation):
  // 0 when it has none yet.
  std::uint64_t classifiedAs = 0;
  std::uint64_t bytes() const { return scene ? scene->bytes() : brick.byteSize(); }
  // This rank's part of the frame (BrickRenderer::render, or the scene's).
  core::Image render(const core::Camera& camera, const core::RenderOptions& options, core::ThreadPool& pool,
                     const core::PixelRect* region) const {
    return scene ? scene->renderer->render(camera, options, pool, nullptr, region)
                 : renderer->render(camera, options, pool, nullptr, region);
  }
};

// Builds the renderer over `brick` (timed) and wraps both.
std::shared_ptr<ReadyBrick> makeReady(core::Brick&& brick, int step);

// How the step on screen is classified, for the bricks read ahead: the
// background thread classifies each as it is read (single-threaded, with
// the copies this holds), so a step from the cache goes on screen without
// classifying while the classification it was read under (`generation`)
// is still the one in force. Empty: read-ahead leaves classifying to the
// step's showing.
struct AheadClassifier {
  std::uint64_t generation = 0;
  std::function<void(core::BrickRenderer&)> classify;
};

// What `performance cache` reports for one rank.
struct CacheStats {
  std::uint64_t hits = 0;       // steps found held or being read ahead when needed
  std::uint64_t misses = 0;     // steps read on demand
  std::uint64_t bytesHeld = 0;  // brick bytes of the steps held
  std::uint64_t stepsHeld = 0;
  double readAheadSeconds = 0;  // background reading and preprocessing
  // The background thread's CPU for them (its own clock): what reading
  // ahead takes from the render threads where the cores are all busy.
  double readAheadCpuSeconds = 0;
};

class BrickCache {
 public:
  // Reads this rank's brick of one step; called on the background thread
  // too, so it must not communicate.
  using Reader = std::function<core::Brick(int step)>;
  // Announces this rank's brick of one step to the storage
  // (VolumeSource::prefetchBox); must not communicate either.
  using Prefetcher = std::function<void(int step)>;

  BrickCache() = default;
  BrickCache(const BrickCache&) = delete;
  BrickCache& operator=(const BrickCache&) = delete;
  ~BrickCache() { clear(); }

  // Drops every step (a new volume, tree or ghost layers) and reads with
  // `reader` from now on; a null reader allows no reading ahead. Every
  // step the cache reads, `prefetch` announces first (announce, below). A
  // budget that holds no step reads nothing ahead, but `prefetch` announces
  // the next step, so its read when it is shown finds the file's pages in
  // memory (fetched while the frame before rendered).
  void reset(Reader reader, Prefetcher prefetch = nullptr);
  // Drops every step and the reader.
  void clear() { reset(nullptr); }
  void setBudget(std::uint64_t bytes);
  std::uint64_t budget() const { return budget_; }

  // Keeps `ready` (a step just read by a distribution) if it fits.
  void insert(const std::shared_ptr<ReadyBrick>& ready);
  // The brick of `step`: held or being read ahead (a hit, waiting for the
  // read to end), or read now on this thread (a miss). Throws what the
  // reader throws.
  std::shared_ptr<ReadyBrick> take(int step);
  // Reads `steps` (in the order they will be shown) on the background
  // thread, as many as the budget holds. Replaces any earlier list; a read
  // in progress goes on. When the budget holds no step, announces the
  // first of them (reset's prefetch) instead.
  void readAhead(std::vector<int> steps);
  // The classification of bricks read ahead from now on (a read in
  // progress keeps the one it started with).
  void classifyAhead(AheadClassifier classifier);

  CacheStats stats() const;

 private:
  // Announces `step` to the storage (prefetch_) just before the cache
  // reads it, on either thread, so a lent brick (raw_reader.cpp) maps pages
  // the announcement put in the page cache. Unannounced, its pages come in
  // by faults, which fill the cache with large folios: on this project's VM
  // the first touch of a cold 2 MiB slab read that way cost 5-8 ms of CPU
  // (no fault counted: the time is the hypervisor's, likely backing memory
  // it had taken back), announced 0.2 ms plus 0.3-0.4 ms of the calls. The
  // read-ahead thread spent 6 ms a step of a 256^3 series on 8 ranks
  // before, 1.2 ms after (bench/results/scale/series_cache5.md).
  void announce(int step) const;
  void stopReadAhead();  // waits for the background thread
  void readAheadLoop();  // the background thread: reads queued_ in order
  // Under mutex_: makes room for `bytes`, evicting steps not in `keep`
  // (and never one somebody else holds). False if it cannot.
  bool makeRoom(std::uint64_t bytes, const std::vector<int>& keep, bool evictWanted);
  void holdLocked(const std::shared_ptr<ReadyBrick>& ready);  // under mutex_
  void touchLocked(int step);
  void evictLocked(int step);  // under mutex_

  Reader reader_;
  Prefetcher prefetch_;
  AheadClassifier classifier_;
  std::uint64_t budget_ = 0;
  mutable std::mutex mutex_;
  std::condition_variable done_;  // a background read ended
  std::map<int, std::shared_ptr<ReadyBrick>> held_;
  std::list<int> recent_;  // held steps, most recently used first
  std::vector<int> wanted_;  // the upcoming steps of the last readAhead
  std::uint64_t stepBytes_ = 0;  // one step's brick bytes, once one was read
  int reading_ = -1;  // the step the background thread is reading; -1: none
  std::vector<int> queued_;  // the steps it will read after that, in order
  bool stop_ = false;    // the background thread ends after its current read
  bool active_ = false;  // the background thread is running
  std::thread worker_;
  CacheStats stats_;
};

}  // namespace pvr::node
