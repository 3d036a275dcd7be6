#include "in_process_communicator.h"

#include <exception>
#include <thread>

namespace pvr::comm {

InProcessWorld::InProcessWorld(int ranks, std::chrono::milliseconds receiveTimeout)
    : ranks_(ranks), timeout_(receiveTimeout) {
  if (ranks < 1) throw Error(ErrorCode::kInvalidArgument, "in-process world needs at least one rank");
}

void InProcessWorld::post(int from, int to, int tag, Bytes data) {
  {
    std::lock_guard lock(mutex_);
    queues_[{from, to, tag}].push_back(std::move(data));
  }
  arrived_.notify_all();
}

Bytes InProcessWorld::take(int from, int to, int tag) {
  std::unique_lock lock(mutex_);
  auto& queue = queues_[{from, to, tag}];
  if (!arrived_.wait_for(lock, timeout_, [&] { return !queue.empty(); }))
    throw Error(ErrorCode::kInternal, "in-process receive: rank " + std::to_string(to) +
                                          " waited too long for rank " + std::to_string(from) +
                                          " tag " + std::to_string(tag) + " (a deadlock?)");
  Bytes data = std::move(queue.front());
  queue.pop_front();
  return data;
}

void InProcessCommunicator::checkRank(int r, const char* what) const {
  if (r < 0 || r >= size())
    throw Error(ErrorCode::kInternal, std::string(what) + ": rank " + std::to_string(r) +
                                          " outside 0.." + std::to_string(size() - 1));
}

void InProcessCommunicator::send(int to, int tag, std::span<const std::byte> data) {
  checkRank(to, "send");
  world_.post(rank_, to, tag, Bytes(data.begin(), data.end()));
}

Bytes InProcessCommunicator::receive(int from, int tag) {
  checkRank(from, "receive");
  return world_.take(from, rank_, tag);
}

Bytes InProcessCommunicator::sendReceive(int to, std::span<const std::byte> data, int from, int tag) {
  send(to, tag, data);  // never blocks here
  return receive(from, tag);
}

std::vector<Bytes> InProcessCommunicator::exchange(std::span<const Outgoing> sends,
                                                   std::span<const int> from, int tag) {
  for (const Outgoing& s : sends) send(s.to, tag, s.data);
  std::vector<Bytes> received;
  received.reserve(from.size());
  for (int f : from) received.push_back(receive(f, tag));
  return received;
}

void runInProcess(int ranks, const std::function<void(Communicator&)>& body) {
  InProcessWorld world(ranks);
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(ranks));
  std::vector<std::thread> threads;
  for (int r = 0; r < ranks; ++r)
    threads.emplace_back([&, r] {
      InProcessCommunicator comm(world, r);
      try {
        body(comm);
      } catch (...) {
        errors[std::size_t(r)] = std::current_exception();
      }
    });
  for (auto& t : threads) t.join();
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace pvr::comm
