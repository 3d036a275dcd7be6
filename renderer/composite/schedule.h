// Who talks to whom, and which part of the frame each rank keeps: the pure
// functions behind every strategy, tested serially (no communicator).
//
// Everything follows the k-d tree's rank structure. Ranks are numbered in
// tree order, so a subtree holds ranks [rankBegin, rankEnd); composite
// images of two sibling subtrees are always adjacent in visibility order,
// whatever the view, which is what makes pairing across a split correct
// ("over" is associative, not commutative).
#pragma once

#include <functional>
#include <vector>

#include "decompose/kd_tree.h"
#include "image.h"

namespace pvr::composite {

struct RankNode {
  int rankBegin = 0, rankEnd = 0;
  int left = -1, right = -1;  // child node indices; -1 for a leaf
  bool leaf() const { return left < 0; }
  int ranks() const { return rankEnd - rankBegin; }
};
// Node 0 is the root; node indices are those of the KdTree it came from.
using RankTopology = std::vector<RankNode>;

// The rank structure KdTree::build gives n ranks: a node of n ranks has
// floor(n/2) on the left and ceil(n/2) on the right.
RankTopology splitTopology(int ranks);
RankTopology topologyOf(const core::KdTree& tree);

// One step of the naive binary-tree reduction of a subtree into its first
// rank. At `node`, the first rank of the right subtree sends its whole
// composite image to the first rank of the left subtree (and is done); the
// receiver composites it behind or in front according to leftInFront(node).
struct ReduceStep {
  int node = 0;
  int partner = 0;
  bool send = false;  // true: send my image to partner and stop
};
// The steps of `rank` reducing subtree `node` into its first rank, deepest
// first. Every rank of the subtree but the first ends with one send.
std::vector<ReduceStep> treeReduceSchedule(const RankTopology& topo, int rank, int node = 0);

// Binary swap on n ranks, any n, following the tree.
//
// With m the largest power of two <= n, the tree is assigned a target of m
// active ranks at the root, m/2 to each child, and so on. A subtree whose
// target is 1 first folds into its first rank by the tree reduction above
// (the n - m extra ranks send their images once, before any swap, and stay
// idle afterwards). Then log2(m) swap rounds: in round j (from the bottom)
// active index i swaps with active index i ^ (1 << j), which lies across the
// split of the node where both subtrees have target 2^j: the trick of the
// paper (partner = rank ^ (1 << round)) with active indices in place of
// ranks. For n a power of two nobody folds and the active index is the rank.
struct SwapTree {
  int rounds = 0;                             // log2(m)
  std::vector<int> actives;                   // rank of each active index, m of them
  std::vector<int> activeIndexOfRank;         // -1 for a folded rank
  std::vector<std::vector<ReduceStep>> fold;  // per rank, before the swaps
  // swapNodes[j][i >> (j + 1)]: the node whose split separates active index
  // i from its round-j partner.
  std::vector<std::vector<int>> swapNodes;
};
SwapTree swapTree(const RankTopology& topo);

// True when active index p's image lies in front of q's (p != q): at the
// node where they part, p is on the left exactly when the left is in front.
bool activeInFront(const SwapTree& swap, int p, int q, const std::function<bool(int node)>& leftInFront);

struct SwapRound {
  int partner = 0;         // rank
  int node = 0;            // the tree node split between us
  bool inLeft = false;     // this rank is in node's left subtree
  bool keepLower = false;  // keep the lower half of the current region (the left subtree does)
};
struct BinarySwapSchedule {
  std::vector<ReduceStep> fold;  // first; a folded rank's last step is its send
  bool active = false;           // holds a tile after the swaps
  std::vector<SwapRound> rounds;  // empty for a folded rank
};
BinarySwapSchedule binarySwapSchedule(const SwapTree& swap, int rank);
BinarySwapSchedule binarySwapSchedule(int rank, int ranks);

// Radix-k: the same active ranks and rounds, but each round merges
// log2(k) binary-swap rounds into one: a group of k active indices that
// differ only in those bits (a subtree of depth log2(k) of the swap tree)
// splits its region into k pieces and every member sends each other member
// its piece (direct send inside the group). The last round takes the bits
// left over. k must be a power of two >= 2 (the k-d tree splits in two);
// k = 2 is binary swap, message for message.
struct RadixRound {
  int firstBit = 0, bits = 0;  // the active-index bits this round resolves
  std::vector<int> members;    // active indices of the group, by digit
  int digit = 0;               // this rank's position in members
};
struct RadixKSchedule {
  std::vector<ReduceStep> fold;
  bool active = false;
  int activeIndex = -1;
  std::vector<RadixRound> rounds;
};
RadixKSchedule radixKSchedule(const SwapTree& swap, int rank, int k);

// Regions. A region is halved across its longer side (x on a tie); the
// lower half is the left or top one. pieceOf applies `bits` halvings,
// choosing the half by the bits of `digit`, lowest bit first: a rank's
// region after binary-swap rounds f..f+bits-1 is pieceOf(region, its
// index >> f, bits).
std::pair<core::PixelRect, core::PixelRect> halve(const core::PixelRect& region);
core::PixelRect pieceOf(core::PixelRect region, int digit, int bits);
// The region of active index i after all rounds of a swap tree.
core::PixelRect finalTile(const core::PixelRect& frame, int activeIndex, int rounds);
// Direct send's tiles: the frame split like the tree (across the longer
// side, in proportion to the ranks on each side), one tile per rank.
std::vector<core::PixelRect> partitionFrame(const core::PixelRect& frame, const RankTopology& topo);

}  // namespace pvr::composite
