#include "schedule.h"

#include <bit>

#include "error.h"

namespace pvr::composite {

using core::PixelRect;

namespace {

int buildSplit(RankTopology& topo, int rankBegin, int rankEnd) {
  const int index = int(topo.size());
  topo.push_back({rankBegin, rankEnd, -1, -1});
  const int n = rankEnd - rankBegin;
  if (n > 1) {
    const int middle = rankBegin + n / 2;
    const int left = buildSplit(topo, rankBegin, middle);
    const int right = buildSplit(topo, middle, rankEnd);
    topo[std::size_t(index)].left = left;
    topo[std::size_t(index)].right = right;
  }
  return index;
}

const RankNode& nodeAt(const RankTopology& topo, int node) {
  if (node < 0 || node >= int(topo.size()))
    throw Error(ErrorCode::kInternal, "rank topology: node " + std::to_string(node) + " out of range");
  return topo[std::size_t(node)];
}

// Gives subtree `node` a target of `target` active ranks (a power of two no
// larger than its rank count), appending its actives in tree order.
void assignTargets(const RankTopology& topo, int node, int target, SwapTree& out) {
  const RankNode& n = nodeAt(topo, node);
  if (target == 1) {
    for (int r = n.rankBegin; r < n.rankEnd; ++r) out.fold[std::size_t(r)] = treeReduceSchedule(topo, r, node);
    out.activeIndexOfRank[std::size_t(n.rankBegin)] = int(out.actives.size());
    out.actives.push_back(n.rankBegin);
    return;
  }
  if (n.leaf() || target / 2 > nodeAt(topo, n.left).ranks())
    throw Error(ErrorCode::kInternal, "swap tree: subtree too small for its target");
  assignTargets(topo, n.left, target / 2, out);
  assignTargets(topo, n.right, target / 2, out);
  // Nodes of one target are reached left to right, so push_back numbers them by block.
  out.swapNodes[std::size_t(std::countr_zero(unsigned(target)) - 1)].push_back(node);
}

void partitionInto(const RankTopology& topo, int node, const PixelRect& region,
                   std::vector<PixelRect>& tiles) {
  const RankNode& n = nodeAt(topo, node);
  if (n.leaf()) {
    tiles[std::size_t(n.rankBegin)] = region;
    return;
  }
  // Cut across the longer side in proportion to the ranks on each side.
  const double share = double(nodeAt(topo, n.left).ranks()) / double(n.ranks());
  PixelRect lower = region, upper = region;
  if (region.width() >= region.height()) {
    const int cut = region.x0 + int(double(region.width()) * share + 0.5);
    lower.x1 = upper.x0 = cut;
  } else {
    const int cut = region.y0 + int(double(region.height()) * share + 0.5);
    lower.y1 = upper.y0 = cut;
  }
  partitionInto(topo, n.left, lower, tiles);
  partitionInto(topo, n.right, upper, tiles);
}

}  // namespace

RankTopology splitTopology(int ranks) {
  if (ranks < 1) throw Error(ErrorCode::kInvalidArgument, "rank topology needs at least one rank");
  RankTopology topo;
  buildSplit(topo, 0, ranks);
  return topo;
}

RankTopology topologyOf(const core::KdTree& tree) {
  RankTopology topo;
  topo.reserve(tree.nodes().size());
  for (const core::KdNode& n : tree.nodes()) topo.push_back({n.rankBegin, n.rankEnd, n.left, n.right});
  return topo;
}

std::vector<ReduceStep> treeReduceSchedule(const RankTopology& topo, int rank, int node) {
  const RankNode& n = nodeAt(topo, node);
  if (rank < n.rankBegin || rank >= n.rankEnd)
    throw Error(ErrorCode::kInternal, "tree reduction: rank outside the subtree");
  if (n.leaf()) return {};
  const bool inLeft = rank < nodeAt(topo, n.left).rankEnd;
  std::vector<ReduceStep> steps = treeReduceSchedule(topo, rank, inLeft ? n.left : n.right);
  if (!steps.empty() && steps.back().send) return steps;  // already handed its image up
  // Here rank is the first rank of its child: the one holding that child's composite.
  if (inLeft)
    steps.push_back({node, nodeAt(topo, n.right).rankBegin, false});
  else
    steps.push_back({node, nodeAt(topo, n.left).rankBegin, true});
  return steps;
}

SwapTree swapTree(const RankTopology& topo) {
  const int n = nodeAt(topo, 0).ranks();
  SwapTree out;
  out.rounds = std::bit_width(unsigned(n)) - 1;
  out.fold.resize(std::size_t(n));
  out.activeIndexOfRank.assign(std::size_t(n), -1);
  out.swapNodes.resize(std::size_t(out.rounds));
  assignTargets(topo, 0, 1 << out.rounds, out);
  return out;
}

bool activeInFront(const SwapTree& swap, int p, int q, const std::function<bool(int node)>& leftInFront) {
  const int j = std::bit_width(unsigned(p ^ q)) - 1;  // the highest bit where they differ
  const int node = swap.swapNodes[std::size_t(j)][std::size_t(p >> (j + 1))];
  const bool pLeft = ((p >> j) & 1) == 0;
  return pLeft == leftInFront(node);
}

BinarySwapSchedule binarySwapSchedule(const SwapTree& swap, int rank) {
  BinarySwapSchedule s;
  s.fold = swap.fold[std::size_t(rank)];
  const int i = swap.activeIndexOfRank[std::size_t(rank)];
  s.active = i >= 0;
  if (!s.active) return s;
  for (int j = 0; j < swap.rounds; ++j) {
    SwapRound round;
    round.partner = swap.actives[std::size_t(i ^ (1 << j))];
    round.node = swap.swapNodes[std::size_t(j)][std::size_t(i >> (j + 1))];
    round.inLeft = ((i >> j) & 1) == 0;
    round.keepLower = round.inLeft;
    s.rounds.push_back(round);
  }
  return s;
}

BinarySwapSchedule binarySwapSchedule(int rank, int ranks) {
  return binarySwapSchedule(swapTree(splitTopology(ranks)), rank);
}

RadixKSchedule radixKSchedule(const SwapTree& swap, int rank, int k) {
  if (k < 2 || !std::has_single_bit(unsigned(k)))
    throw Error(ErrorCode::kInvalidArgument,
                "radix-k: k = " + std::to_string(k) + " must be a power of two >= 2 (the k-d tree splits in two)");
  const int bitsPerRound = std::countr_zero(unsigned(k));
  RadixKSchedule s;
  s.fold = swap.fold[std::size_t(rank)];
  s.activeIndex = swap.activeIndexOfRank[std::size_t(rank)];
  s.active = s.activeIndex >= 0;
  if (!s.active) return s;
  for (int first = 0; first < swap.rounds; first += bitsPerRound) {
    RadixRound round;
    round.firstBit = first;
    round.bits = std::min(bitsPerRound, swap.rounds - first);
    const int mask = ((1 << round.bits) - 1) << first;
    const int base = s.activeIndex & ~mask;
    for (int d = 0; d < (1 << round.bits); ++d) round.members.push_back(base | (d << first));
    round.digit = (s.activeIndex & mask) >> first;
    s.rounds.push_back(std::move(round));
  }
  return s;
}

std::pair<PixelRect, PixelRect> halve(const PixelRect& region) {
  PixelRect lower = region, upper = region;
  if (region.width() >= region.height()) {
    lower.x1 = upper.x0 = region.x0 + region.width() / 2;
  } else {
    lower.y1 = upper.y0 = region.y0 + region.height() / 2;
  }
  return {lower, upper};
}

PixelRect pieceOf(PixelRect region, int digit, int bits) {
  for (int b = 0; b < bits; ++b) {
    const auto [lower, upper] = halve(region);
    region = ((digit >> b) & 1) == 0 ? lower : upper;
  }
  return region;
}

PixelRect finalTile(const PixelRect& frame, int activeIndex, int rounds) {
  return pieceOf(frame, activeIndex, rounds);
}

std::vector<PixelRect> partitionFrame(const PixelRect& frame, const RankTopology& topo) {
  std::vector<PixelRect> tiles(std::size_t(nodeAt(topo, 0).ranks()));
  partitionInto(topo, 0, frame, tiles);
  return tiles;
}

}  // namespace pvr::composite
