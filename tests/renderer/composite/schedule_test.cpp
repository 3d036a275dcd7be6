// Partner and region logic of the strategies, serially: no communicator.
#include <catch2/catch.hpp>

#include <algorithm>
#include <bit>
#include <set>

#include "error.h"
#include "schedule.h"

using namespace pvr::composite;
using pvr::core::PixelRect;

TEST_CASE("split topology gives floor(n/2) ranks left and ceil(n/2) right", "[schedule]") {
  for (int n = 1; n <= 17; ++n) {
    const RankTopology topo = splitTopology(n);
    CHECK(topo[0].rankBegin == 0);
    CHECK(topo[0].rankEnd == n);
    int leaves = 0;
    for (const RankNode& node : topo) {
      if (node.leaf()) {
        CHECK(node.ranks() == 1);
        ++leaves;
        continue;
      }
      CHECK(topo[std::size_t(node.left)].ranks() == node.ranks() / 2);
      CHECK(topo[std::size_t(node.right)].ranks() == (node.ranks() + 1) / 2);
      CHECK(topo[std::size_t(node.left)].rankEnd == topo[std::size_t(node.right)].rankBegin);
    }
    CHECK(leaves == n);
  }
}

TEST_CASE("binary swap partners are rank ^ (1 << round) for powers of two", "[schedule]") {
  for (int n : {1, 2, 4, 8, 16}) {
    for (int r = 0; r < n; ++r) {
      const BinarySwapSchedule s = binarySwapSchedule(r, n);
      CHECK(s.fold.empty());
      CHECK(s.active);
      REQUIRE(int(s.rounds.size()) == std::countr_zero(unsigned(n)));
      for (int j = 0; j < int(s.rounds.size()); ++j) {
        CHECK(s.rounds[std::size_t(j)].partner == (r ^ (1 << j)));
        // The lower rank is on the left of the split and keeps the lower half.
        CHECK(s.rounds[std::size_t(j)].keepLower == (r < (r ^ (1 << j))));
      }
    }
  }
}

TEST_CASE("binary swap partners are mutual and lie across the same split", "[schedule]") {
  for (int n = 1; n <= 16; ++n) {
    const RankTopology topo = splitTopology(n);
    const SwapTree swap = swapTree(topo);
    const int m = 1 << std::bit_width(unsigned(n)) >> 1;
    CHECK(int(swap.actives.size()) == m);
    for (int r = 0; r < n; ++r) {
      const BinarySwapSchedule s = binarySwapSchedule(swap, r);
      for (std::size_t j = 0; j < s.rounds.size(); ++j) {
        const SwapRound& mine = s.rounds[j];
        const SwapRound theirs = binarySwapSchedule(swap, mine.partner).rounds.at(j);
        CHECK(theirs.partner == r);
        CHECK(theirs.node == mine.node);
        CHECK(theirs.inLeft != mine.inLeft);
        // The split really separates us: I am in the child my flag names.
        const RankNode& node = topo[std::size_t(mine.node)];
        const RankNode& side = topo[std::size_t(mine.inLeft ? node.left : node.right)];
        CHECK((r >= side.rankBegin && r < side.rankEnd));
      }
    }
  }
}

TEST_CASE("binary swap folds exactly n - m ranks, each with one send", "[schedule]") {
  for (int n = 1; n <= 16; ++n) {
    const SwapTree swap = swapTree(splitTopology(n));
    int folded = 0, sends = 0;
    for (int r = 0; r < n; ++r) {
      const BinarySwapSchedule s = binarySwapSchedule(swap, r);
      for (const ReduceStep& step : s.fold) sends += step.send;
      if (!s.active) {
        ++folded;
        REQUIRE(!s.fold.empty());
        CHECK(s.fold.back().send);
        CHECK(s.rounds.empty());
      }
    }
    CHECK(folded == n - int(swap.actives.size()));
    CHECK(sends == folded);
  }
}

TEST_CASE("tree reduction gathers every rank into rank 0 once", "[schedule]") {
  for (int n = 1; n <= 13; ++n) {
    const RankTopology topo = splitTopology(n);
    std::multiset<int> received;  // senders as seen by receivers
    int sends = 0;
    for (int r = 0; r < n; ++r) {
      const auto steps = treeReduceSchedule(topo, r);
      if (r == 0) CHECK(std::none_of(steps.begin(), steps.end(), [](const ReduceStep& s) { return s.send; }));
      for (const ReduceStep& step : steps) {
        if (step.send) {
          ++sends;
          // The receiver expects me at the same node.
          const auto theirs = treeReduceSchedule(topo, step.partner);
          CHECK(std::any_of(theirs.begin(), theirs.end(), [&](const ReduceStep& t) {
            return !t.send && t.partner == r && t.node == step.node;
          }));
        } else {
          received.insert(step.partner);
        }
      }
    }
    CHECK(sends == n - 1);
    CHECK(int(received.size()) == n - 1);
  }
}

TEST_CASE("radix-k with k = 2 is binary swap's pattern", "[schedule]") {
  for (int n = 1; n <= 12; ++n) {
    const SwapTree swap = swapTree(splitTopology(n));
    for (int r = 0; r < n; ++r) {
      const BinarySwapSchedule b = binarySwapSchedule(swap, r);
      const RadixKSchedule k = radixKSchedule(swap, r, 2);
      REQUIRE(k.rounds.size() == b.rounds.size());
      for (std::size_t j = 0; j < b.rounds.size(); ++j) {
        const RadixRound& round = k.rounds[j];
        REQUIRE(round.members.size() == 2);
        const int other = round.members[std::size_t(1 - round.digit)];
        CHECK(swap.actives[std::size_t(other)] == b.rounds[j].partner);
        CHECK((round.digit == 0) == b.rounds[j].keepLower);
      }
    }
  }
}

TEST_CASE("radix-k groups cover log2(k) bits per round, the last takes the rest", "[schedule]") {
  const SwapTree swap = swapTree(splitTopology(32));
  const RadixKSchedule s = radixKSchedule(swap, 13, 4);
  REQUIRE(s.rounds.size() == 3);
  CHECK(s.rounds[0].members == std::vector<int>{12, 13, 14, 15});
  CHECK(s.rounds[0].digit == 1);
  CHECK(s.rounds[1].members == std::vector<int>{1, 5, 9, 13});
  CHECK(s.rounds[1].digit == 3);
  CHECK(s.rounds[2].members == std::vector<int>{13, 29});
  CHECK_THROWS_AS(radixKSchedule(swap, 0, 3), pvr::Error);
  CHECK_THROWS_AS(radixKSchedule(swap, 0, 1), pvr::Error);
}

TEST_CASE("halving regions tiles the frame, final tiles are disjoint and cover it", "[schedule]") {
  const PixelRect frame{0, 0, 37, 23};
  for (int rounds = 0; rounds <= 5; ++rounds) {
    long area = 0;
    std::vector<PixelRect> tiles;
    for (int i = 0; i < (1 << rounds); ++i) tiles.push_back(finalTile(frame, i, rounds));
    for (std::size_t a = 0; a < tiles.size(); ++a) {
      area += long(tiles[a].width()) * tiles[a].height();
      CHECK(tiles[a].intersect(frame) == tiles[a]);
      for (std::size_t b = a + 1; b < tiles.size(); ++b) CHECK(tiles[a].intersect(tiles[b]).empty());
    }
    CHECK(area == 37L * 23);
  }
  // Halving cuts across the longer side.
  CHECK(halve({0, 0, 10, 4}).first == PixelRect{0, 0, 5, 4});
  CHECK(halve({0, 0, 4, 10}).second == PixelRect{0, 5, 4, 10});
}

TEST_CASE("direct send's tiles partition the frame, one per rank", "[schedule]") {
  const PixelRect frame{0, 0, 64, 48};
  for (int n = 1; n <= 9; ++n) {
    const auto tiles = partitionFrame(frame, splitTopology(n));
    REQUIRE(int(tiles.size()) == n);
    long area = 0;
    for (std::size_t a = 0; a < tiles.size(); ++a) {
      area += long(tiles[a].width()) * tiles[a].height();
      for (std::size_t b = a + 1; b < tiles.size(); ++b) CHECK(tiles[a].intersect(tiles[b]).empty());
    }
    CHECK(area == 64L * 48);
  }
}

TEST_CASE("activeInFront follows the split where two actives part", "[schedule]") {
  const SwapTree swap = swapTree(splitTopology(8));
  // Left always in front: tree order is front to back.
  auto leftFront = [](int) { return true; };
  auto rightFront = [](int) { return false; };
  for (int p = 0; p < 8; ++p)
    for (int q = 0; q < 8; ++q) {
      if (p == q) continue;
      CHECK(activeInFront(swap, p, q, leftFront) == (p < q));
      CHECK(activeInFront(swap, p, q, rightFront) == (p > q));
    }
}
