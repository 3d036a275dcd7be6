// The in-process communicator and the default collectives and agreement
// built on its point-to-point messages.
#include <catch2/catch.hpp>

#include <atomic>
#include <mutex>

#include "in_process_communicator.h"
#include "sub_communicator.h"

using namespace pvr::comm;

namespace {

Bytes bytesOf(const std::string& s) {
  const auto* p = reinterpret_cast<const std::byte*>(s.data());
  return Bytes(p, p + s.size());
}

std::string textOf(const Bytes& b) { return std::string(reinterpret_cast<const char*>(b.data()), b.size()); }

}  // namespace

TEST_CASE("in-process messages arrive per (from, tag) in the order sent", "[communicator]") {
  runInProcess(3, [](Communicator& comm) {
    if (comm.rank() == 0) {
      comm.send(1, 5, bytesOf("a"));
      comm.send(1, 6, bytesOf("other tag"));
      comm.send(1, 5, bytesOf("b"));
    } else if (comm.rank() == 1) {
      CHECK(textOf(comm.receive(0, 6)) == "other tag");
      CHECK(textOf(comm.receive(0, 5)) == "a");
      CHECK(textOf(comm.receive(0, 5)) == "b");
    }
  });
}

TEST_CASE("sendReceive and exchange let ranks swap without deadlock", "[communicator]") {
  runInProcess(4, [](Communicator& comm) {
    const int partner = comm.rank() ^ 1;
    const Bytes got = comm.sendReceive(partner, bytesOf(std::to_string(comm.rank())), partner, 1);
    CHECK(textOf(got) == std::to_string(partner));
    // Everyone sends to everyone else.
    std::vector<Bytes> payloads;
    std::vector<Outgoing> sends;
    std::vector<int> from;
    for (int r = 0; r < comm.size(); ++r)
      if (r != comm.rank()) payloads.push_back(bytesOf(std::to_string(comm.rank() * 10 + r)));
    for (int r = 0, i = 0; r < comm.size(); ++r)
      if (r != comm.rank()) {
        sends.push_back({r, payloads[std::size_t(i++)]});
        from.push_back(r);
      }
    const std::vector<Bytes> received = comm.exchange(sends, from, 2);
    for (std::size_t i = 0; i < from.size(); ++i)
      CHECK(textOf(received[i]) == std::to_string(from[i] * 10 + comm.rank()));
  });
}

TEST_CASE("default collectives: broadcast, allGather, allReduce", "[communicator]") {
  for (int n = 1; n <= 5; ++n)
    runInProcess(n, [n](Communicator& comm) {
      Bytes data = comm.rank() == n - 1 ? bytesOf("root says") : Bytes{};
      comm.broadcast(data, n - 1);
      CHECK(textOf(data) == "root says");
      const auto all = comm.allGather(bytesOf(std::string(std::size_t(comm.rank()), 'x')));
      REQUIRE(int(all.size()) == n);
      for (int r = 0; r < n; ++r) CHECK(all[std::size_t(r)].size() == std::size_t(r));
      std::vector<std::uint64_t> sums{std::uint64_t(comm.rank()), 1};
      comm.allReduceSum(sums);
      CHECK(sums[0] == std::uint64_t(n * (n - 1) / 2));
      CHECK(sums[1] == std::uint64_t(n));
      std::vector<double> maxima{double(comm.rank())};
      comm.allReduceMax(maxima);
      CHECK(maxima[0] == n - 1);
      comm.barrier();
    });
}

TEST_CASE("runAgreed: every rank throws the lowest failing rank's error", "[communicator]") {
  std::mutex mutex;
  std::vector<std::string> messages;
  std::atomic<int> thrown{0};
  runInProcess(6, [&](Communicator& comm) {
    try {
      runAgreed(comm, [&] {
        if (comm.rank() == 4) throw pvr::Error(pvr::ErrorCode::kBadFile, "brick.raw: truncated");
        if (comm.rank() == 5) throw std::runtime_error("later failure");
      });
    } catch (const pvr::Error& e) {
      ++thrown;
      CHECK(e.code() == pvr::ErrorCode::kBadFile);
      std::lock_guard lock(mutex);
      messages.push_back(e.what());
    }
    // The communicator still works after an agreed failure.
    runAgreed(comm, [] {});
  });
  CHECK(thrown == 6);
  for (const auto& m : messages) CHECK(m == "rank 4: brick.raw: truncated");
}

TEST_CASE("a failure agreed on a sub-communicator keeps the world rank it came from", "[communicator]") {
  // Two clusters {0,2,4} and {1,3,5}; world rank 4 (sub-rank 2 of the first)
  // fails. Its cluster agrees on it, then the world agrees again: the origin
  // travels as data through both agreements.
  std::atomic<int> seen{0};
  runInProcess(6, [&](Communicator& world) {
    const int parity = world.rank() % 2;
    SubCommunicator cluster(world, parity ? std::vector<int>{1, 3, 5} : std::vector<int>{0, 2, 4});
    CHECK(cluster.worldRank() == world.rank());
    std::optional<Failure> mine;
    try {
      runAgreed(cluster, [&] {
        if (world.rank() == 4) throw pvr::Error(pvr::ErrorCode::kIo, "brick.raw: short read");
      });
    } catch (...) {
      mine = failureOf(std::current_exception(), world.rank());
    }
    const auto agreed = world.agree(mine);
    REQUIRE(agreed);
    CHECK(agreed->origin == 4);
    CHECK(agreed->code == pvr::ErrorCode::kIo);
    CHECK(agreed->describe() == "rank 4: brick.raw: short read");
    ++seen;
  });
  CHECK(seen == 6);
}

TEST_CASE("a failure's bytes round-trip, and a short status is refused", "[communicator]") {
  const Failure f{7, pvr::ErrorCode::kBadFile, "x.nrrd: bad header"};
  const auto back = decodeFailure(encodeFailure(f));
  REQUIRE(back);
  CHECK(back->origin == 7);
  CHECK(back->code == pvr::ErrorCode::kBadFile);
  CHECK(back->message == f.message);
  CHECK_FALSE(decodeFailure(encodeFailure(std::nullopt)));
  const Bytes shortStatus{std::byte{1}, std::byte{0}};
  CHECK_THROWS_AS(decodeFailure(shortStatus), pvr::Error);
}

TEST_CASE("a receive nobody answers times out instead of hanging", "[communicator]") {
  InProcessWorld world(2, std::chrono::milliseconds(50));
  InProcessCommunicator comm(world, 0);
  CHECK_THROWS_AS(comm.receive(1, 7), pvr::Error);
}
