// N ranks as N threads of one process: the communicator of the unit tests.
//
// Every (from, to, tag) has its own queue; send never blocks, receive waits
// for its queue (and gives up after `receiveTimeout`, so a strategy with a
// schedule bug fails a test instead of hanging it).
#pragma once

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <tuple>

#include "communicator.h"

namespace pvr::comm {

class InProcessWorld {
 public:
  explicit InProcessWorld(int ranks, std::chrono::milliseconds receiveTimeout = std::chrono::seconds(60));
  int size() const { return ranks_; }

  void post(int from, int to, int tag, Bytes data);
  Bytes take(int from, int to, int tag);

 private:
  int ranks_;
  std::chrono::milliseconds timeout_;
  std::mutex mutex_;
  std::condition_variable arrived_;
  std::map<std::tuple<int, int, int>, std::deque<Bytes>> queues_;
};

class InProcessCommunicator final : public Communicator {
 public:
  InProcessCommunicator(InProcessWorld& world, int rank) : world_(world), rank_(rank) {}

  int rank() const override { return rank_; }
  int size() const override { return world_.size(); }
  void send(int to, int tag, std::span<const std::byte> data) override;
  Bytes receive(int from, int tag) override;
  Bytes sendReceive(int to, std::span<const std::byte> data, int from, int tag) override;
  std::vector<Bytes> exchange(std::span<const Outgoing> sends, std::span<const int> from,
                              int tag) override;

 private:
  void checkRank(int r, const char* what) const;

  InProcessWorld& world_;
  int rank_;
};

// Runs body(comm) on `ranks` threads, one communicator each, and waits for
// all. Rethrows the exception of the lowest rank that threw, if any.
void runInProcess(int ranks, const std::function<void(Communicator&)>& body);

}  // namespace pvr::comm
