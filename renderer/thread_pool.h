// A fixed pool of worker threads running index-parallel loops.
//
// parallelFor hands out indices through one atomic counter, so tiles that
// are cheap (empty space) and tiles that are dear (dense data) balance
// themselves. The calling thread works too; workers sleep between loops.
#pragma once

#include <algorithm>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

namespace pvr::core {

class ThreadPool {
 public:
  // threads <= 0: one per hardware thread.
  explicit ThreadPool(int threads = 0);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int size() const { return int(workers_.size()) + 1; }

  // Calls body(index, worker) for every index in [0, count), worker in
  // [0, size()). Returns when all are done; rethrows the first exception.
  void parallelFor(std::size_t count, const std::function<void(std::size_t, int)>& body);

 private:
  void workerLoop(int worker);
  void runShare(int worker);

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  const std::function<void(std::size_t, int)>* body_ = nullptr;
  std::size_t count_ = 0;
  std::size_t next_ = 0;        // guarded by mutex_ for hand-out
  std::size_t generation_ = 0;  // bumps once per loop
  int busy_ = 0;
  bool stop_ = false;
  std::exception_ptr error_;
};

// Runs body(begin, end) over contiguous chunks of [0, n): a few chunks per
// thread of the pool (so uneven chunks still balance), or the whole range
// on the calling thread when there is no pool. A body taking a third
// argument gets the worker running the chunk, in [0, pool->size()) (0
// without a pool), for state of its own per thread.
template <typename F>
void forChunks(std::size_t n, ThreadPool* pool, F&& body) {
  auto run = [&](std::size_t begin, std::size_t end, int worker) {
    if constexpr (std::is_invocable_v<F&, std::size_t, std::size_t, int>) body(begin, end, worker);
    else body(begin, end);
  };
  const std::size_t chunks = pool ? std::min<std::size_t>(n, std::size_t(pool->size()) * 4) : 1;
  if (chunks <= 1) {
    if (n > 0) run(std::size_t(0), n, 0);
    return;
  }
  pool->parallelFor(chunks, [&](std::size_t c, int worker) { run(n * c / chunks, n * (c + 1) / chunks, worker); });
}

}  // namespace pvr::core
