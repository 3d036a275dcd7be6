// The render ranks' brick cache (node/brick_cache.h), serially, over a
// procedural volume whose step k reads as a brick filled with k: what it
// holds within its budget, what it evicts first, and that read-ahead turns
// the next steps into hits.
#include <catch2/catch.hpp>
#include <atomic>
#include <mutex>
#include <string>
#include <vector>

#include "brick_cache.h"
#include "io/volume_io.h"

using namespace pvr;
using node::BrickCache;

namespace {

constexpr int kSide = 16;  // one step: 16^3 float32 = 16 KiB

// A reader whose step k is a brick of the whole grid with every value k;
// counts its calls.
struct StepReader {
  std::unique_ptr<core::VolumeSource> source = core::openProcedural("constant-slab", {kSide, kSide, kSide});
  std::shared_ptr<std::atomic<int>> reads = std::make_shared<std::atomic<int>>(0);
  BrickCache::Reader reader() const {
    return [src = source.get(), reads = reads](int step) {
      ++*reads;
      core::Brick b = src->readAll();
      for (std::int64_t i = 0; i < b.stored().nodeCount(); ++i) b.as<float>()[i] = float(step);
      b.updateValueRange();
      return b;
    };
  }
};

constexpr std::uint64_t kStepBytes = std::uint64_t(kSide) * kSide * kSide * 4;

}  // namespace

TEST_CASE("the brick cache holds steps within its budget and evicts the least recently used first") {
  StepReader steps;
  BrickCache cache;
  cache.setBudget(2 * kStepBytes);  // two steps
  cache.reset(steps.reader());
  // Each take of a step not held reads it (a miss) and keeps it.
  CHECK(cache.take(0)->brick.valueRange().max == 0);
  CHECK(cache.take(1)->brick.valueRange().max == 1);
  CHECK(cache.take(0)->step == 0);  // held: a hit
  CHECK(cache.stats().hits == 1);
  CHECK(cache.stats().misses == 2);
  CHECK(cache.stats().bytesHeld == 2 * kStepBytes);
  // Step 2 evicts step 1, used longest ago.
  cache.take(2);
  CHECK(cache.stats().stepsHeld == 2);
  cache.take(0);
  CHECK(cache.stats().hits == 2);
  cache.take(1);
  CHECK(cache.stats().misses == 4);
  CHECK(*steps.reads == 4);
}

TEST_CASE("a budget below one step holds nothing and every step is read when needed") {
  StepReader steps;
  BrickCache cache;
  cache.setBudget(kStepBytes - 1);
  cache.reset(steps.reader());
  cache.readAhead({1, 2});  // nothing fits: nothing is read ahead
  for (int pass = 0; pass < 2; ++pass)
    for (int k = 0; k < 3; ++k) CHECK(cache.take(k)->brick.valueRange().min == k);
  CHECK(cache.stats().hits == 0);
  CHECK(cache.stats().misses == 6);
  CHECK(cache.stats().bytesHeld == 0);
}

TEST_CASE("a budget below one step announces the next step to the storage, and one that holds steps reads it") {
  StepReader steps;
  BrickCache cache;
  std::vector<int> announced;
  cache.setBudget(kStepBytes - 1);
  cache.reset(steps.reader(), [&](int step) { announced.push_back(step); });
  cache.take(0);      // one step read: its size is known to exceed the budget
  announced.clear();  // (it was announced as it was read)
  cache.readAhead({1, 2});
  CHECK(announced == std::vector<int>{1});  // the next one only
  CHECK(*steps.reads == 1);                  // and nothing read ahead
  // A budget of two steps reads them ahead instead (announcing each as it
  // reads it: the next test).
  cache.setBudget(2 * kStepBytes);
  cache.readAhead({1, 2});
  CHECK(cache.take(1)->step == 1);
  CHECK(cache.take(2)->step == 2);
  CHECK(cache.stats().hits == 2);
  CHECK(*steps.reads == 3);
}

TEST_CASE("every step the cache reads, ahead or on demand, is announced to the storage just before") {
  // A lent brick whose pages are announced first comes from the page cache
  // the announcement filled; one brought in by faults alone cost its reading
  // thread 12-16x the CPU on this project's VM (brick_cache.h, announce).
  StepReader steps;
  BrickCache cache;
  std::mutex mutex;  // the background thread logs too
  std::vector<std::string> log;
  auto note = [&](std::string what) {
    std::lock_guard lock(mutex);
    log.push_back(std::move(what));
  };
  const BrickCache::Reader read = steps.reader();
  cache.setBudget(3 * kStepBytes);
  cache.reset([&](int step) {
                note("read " + std::to_string(step));
                return read(step);
              },
              [&](int step) { note("announce " + std::to_string(step)); });
  cache.take(0);  // a miss, read on this thread
  cache.readAhead({1, 2});
  CHECK(cache.take(1)->step == 1);
  CHECK(cache.take(2)->step == 2);
  CHECK(cache.stats().hits == 2);
  std::lock_guard lock(mutex);
  CHECK(log == std::vector<std::string>{"announce 0", "read 0", "announce 1", "read 1", "announce 2", "read 2"});
}

TEST_CASE("read-ahead makes the upcoming steps hits, and never evicts a step on screen") {
  StepReader steps;
  BrickCache cache;
  cache.setBudget(3 * kStepBytes);
  cache.reset(steps.reader());
  const std::shared_ptr<node::ReadyBrick> onScreen = cache.take(0);
  cache.readAhead({1, 2, 3});  // room for two beside the step on screen
  CHECK(cache.take(1)->step == 1);
  CHECK(cache.take(2)->step == 2);
  CHECK(cache.stats().hits == 2);
  CHECK(cache.stats().misses == 1);
  CHECK(cache.stats().readAheadSeconds > 0);
  // The background thread's CPU for those reads: some, within their wall time.
  CHECK(cache.stats().readAheadCpuSeconds > 0);
  CHECK(cache.stats().readAheadCpuSeconds <= cache.stats().readAheadSeconds + 1e-3);
  // Step 3 did not fit: read now, evicting 1 (used before 2), not 0.
  cache.take(3);
  CHECK(cache.stats().misses == 2);
  cache.take(0);
  CHECK(cache.stats().hits == 3);
  // A smaller budget drops steps at once.
  cache.setBudget(kStepBytes);
  CHECK(cache.stats().bytesHeld <= kStepBytes);
  CHECK(onScreen->brick.valueRange().max == 0);  // its owner still has it
}
