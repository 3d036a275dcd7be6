#include "kd_tree.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <utility>

#include "../error.h"
#include "content.h"

namespace pvr::core {

namespace {

// Cells per axis of a node box; 0 on an axis where the grid has no cells.
using CellCounts = std::array<std::int64_t, 3>;

CellCounts cellsOf(const NodeBox& box) {
  return {box.hi.x - box.lo.x, box.hi.y - box.lo.y, box.hi.z - box.lo.z};
}

std::string cellsText(const CellCounts& c) {
  return std::to_string(c[0]) + "x" + std::to_string(c[1]) + "x" + std::to_string(c[2]);
}

// Which boxes can hold a subtree of n ranks.
//
// A box is feasible for n ranks when n == 1, or when some axis has a plane
// whose two sides are feasible for floor(n/2) and ceil(n/2) ranks. A larger
// box is feasible whenever a smaller one is (the same planes still work), so
// on one axis the left side is feasible for every plane from some first one
// on, the right side up to some last one: the usable planes are an interval,
// found by two binary searches. Results depend only on the cell counts and
// n, and are memoised; the common case (some axis has at least n cells: cut
// it into n slabs) answers at once.
class Feasibility {
 public:
  bool feasible(const CellCounts& c, int n) {
    if (n <= 1) return true;
    double capacity = 1;
    for (std::int64_t x : c) capacity *= double(std::max<std::int64_t>(x, 1));
    if (capacity < double(n)) return false;
    for (std::int64_t x : c)
      if (x >= n) return true;
    const auto key = std::make_pair(c, n);
    if (const auto it = memo_.find(key); it != memo_.end()) return it->second;
    bool ok = false;
    for (int a = 0; a < 3 && !ok; ++a) {
      const auto [first, last] = planes(c, a, n);
      ok = first <= last;
    }
    memo_.emplace(key, ok);
    return ok;
  }

  // The usable planes on `axis` for n ranks, as cells left of the plane:
  // [first, last], empty (first > last) when there is none.
  std::pair<std::int64_t, std::int64_t> planes(const CellCounts& c, int axis, int n) {
    if (c[axis] < 2) return {1, 0};
    const int left = n / 2, right = n - left;
    const std::int64_t leftCells = minCells(c, axis, left);
    const std::int64_t rightCells = minCells(c, axis, right);
    return {leftCells, c[axis] - rightCells};
  }

 private:
  // Fewest cells on `axis` (at most c[axis] - 1) that hold n ranks, the
  // other axes as in c; c[axis] when even c[axis] - 1 does not.
  std::int64_t minCells(CellCounts c, int axis, int n) {
    std::int64_t lo = 1, hi = c[axis];
    while (lo < hi) {
      const std::int64_t mid = lo + (hi - lo) / 2;
      c[axis] = mid;
      if (feasible(c, n))
        hi = mid;
      else
        lo = mid + 1;
    }
    return lo;
  }

  std::map<std::pair<CellCounts, int>, bool> memo_;
};

class TreeBuilder {
 public:
  TreeBuilder(const GridGeometry& grid, SplitAxisRule rule, const ContentGrid* content,
              std::vector<KdNode>& nodes, std::vector<int>& leafOfRank)
      : grid_(grid), rule_(rule), content_(content), nodes_(nodes), leafOfRank_(leafOfRank) {}

  void build(int ranks) {
    const NodeBox all = grid_.allNodes();
    if (!feasibility_.feasible(cellsOf(all), ranks))
      throw Error(ErrorCode::kInvalidArgument,
                  "k-d tree: the grid's " + cellsText(cellsOf(all)) +
                      " cells cannot be split into " + std::to_string(ranks) +
                      " bricks of at least one cell per axis by halving the rank count");
    leafOfRank_.assign(std::size_t(ranks), -1);
    subtree(all, 0, ranks, 0);
  }

 private:
  // Adds the subtree of ranks [rankBegin, rankEnd) over `box` in preorder;
  // returns its node index. `firstAxis` is where kAlternating starts.
  int subtree(const NodeBox& box, int rankBegin, int rankEnd, int firstAxis) {
    const int index = int(nodes_.size());
    KdNode node;
    node.box = box;
    node.rankBegin = rankBegin;
    node.rankEnd = rankEnd;
    nodes_.push_back(node);
    const int n = rankEnd - rankBegin;
    if (n == 1) {
      leafOfRank_[std::size_t(rankBegin)] = index;
      return index;
    }

    // The first axis in rule order with a usable plane; the proportional
    // plane, moved into the usable interval if it would starve a side.
    const CellCounts cells = cellsOf(box);
    const int leftRanks = n / 2;
    for (int axis : axisOrder(cells, firstAxis)) {
      const auto [first, last] = feasibility_.planes(cells, axis, n);
      if (first > last) continue;
      const std::int64_t cut = std::clamp(idealCut(box, axis, leftRanks, n), first, last);
      const std::int64_t plane = box.lo[axis] + cut;
      nodes_[std::size_t(index)].axis = axis;
      nodes_[std::size_t(index)].plane = plane;

      NodeBox leftBox = box, rightBox = box;
      leftBox.hi[axis] = plane;
      rightBox.lo[axis] = plane;
      const int next = (axis + 1) % 3;
      const int left = subtree(leftBox, rankBegin, rankBegin + leftRanks, next);
      const int right = subtree(rightBox, rankBegin + leftRanks, rankEnd, next);
      nodes_[std::size_t(index)].left = left;
      nodes_[std::size_t(index)].right = right;
      return index;
    }
    throw Error(ErrorCode::kInternal, "k-d tree: no usable plane in " + toString(box) + " for " +
                                          std::to_string(n) + " ranks");
  }

  std::array<int, 3> axisOrder(const CellCounts& cells, int firstAxis) const {
    std::array<int, 3> order{firstAxis, (firstAxis + 1) % 3, (firstAxis + 2) % 3};
    if (rule_ == SplitAxisRule::kSlowest) return {2, 1, 0};
    if (rule_ == SplitAxisRule::kLongest) {
      order = {0, 1, 2};
      std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
        return double(cells[a]) * grid_.spacing[a] > double(cells[b]) * grid_.spacing[b];
      });
    }
    return order;
  }

  // Cells left of the plane that would give the left side leftRanks/n of
  // the box's cells (plain) or content (balanced), before feasibility.
  std::int64_t idealCut(const NodeBox& box, int axis, int leftRanks, int n) const {
    const std::int64_t cells = box.hi[axis] - box.lo[axis];
    const std::int64_t byCells = (2 * cells * leftRanks + n) / (2 * std::int64_t(n));
    if (!content_) return byCells;

    const std::vector<double> profile = contentProfile(box, axis);
    double total = 0;
    for (double w : profile) total += w;
    if (!(total > 0)) return byCells;
    // The cut whose left content is nearest the target.
    const double target = total * leftRanks / n;
    std::int64_t best = 1;
    double bestMiss = -1, leftContent = 0;
    for (std::int64_t cut = 1; cut < cells; ++cut) {
      leftContent += profile[std::size_t(cut - 1)];
      const double miss = std::abs(leftContent - target);
      if (bestMiss < 0 || miss < bestMiss) best = cut, bestMiss = miss;
    }
    return best;
  }

  // Content of each cell slab of `box` across `axis`, a block's count
  // spread evenly over the block's cells. An axis without cells is one
  // virtual cell in block 0.
  std::vector<double> contentProfile(const NodeBox& box, int axis) const {
    const ContentGrid& c = *content_;
    std::int64_t cellLo[3], cellHi[3], gridCells[3];
    for (int a = 0; a < 3; ++a) {
      const bool hasCells = grid_.dims[a] > 1;
      gridCells[a] = hasCells ? grid_.dims[a] - 1 : 1;
      cellLo[a] = hasCells ? box.lo[a] : 0;
      cellHi[a] = hasCells ? box.hi[a] : 1;
    }
    std::vector<double> profile(std::size_t(cellHi[axis] - cellLo[axis]), 0.0);
    std::int64_t firstBlock[3], lastBlock[3];
    for (int a = 0; a < 3; ++a) {
      firstBlock[a] = cellLo[a] / c.blockCells[a];
      lastBlock[a] = (cellHi[a] - 1) / c.blockCells[a];
    }
    for (std::int64_t bz = firstBlock[2]; bz <= lastBlock[2]; ++bz)
      for (std::int64_t by = firstBlock[1]; by <= lastBlock[1]; ++by)
        for (std::int64_t bx = firstBlock[0]; bx <= lastBlock[0]; ++bx) {
          const std::uint64_t count =
              c.counts[std::size_t((bz * c.blocks.y + by) * c.blocks.x + bx)];
          if (count == 0) continue;
          // The block's cells, the part of them inside the box, and the
          // share of the count that part holds across the other axes.
          const std::int64_t block[3] = {bx, by, bz};
          std::int64_t blockLo[3], blockHi[3], inLo[3], inHi[3];
          double weight = double(count);
          for (int a = 0; a < 3; ++a) {
            blockLo[a] = block[a] * c.blockCells[a];
            blockHi[a] = std::min(blockLo[a] + c.blockCells[a], gridCells[a]);
            inLo[a] = std::max(blockLo[a], cellLo[a]);
            inHi[a] = std::min(blockHi[a], cellHi[a]);
            if (a != axis) weight *= double(inHi[a] - inLo[a]) / double(blockHi[a] - blockLo[a]);
          }
          const double perCell = weight / double(blockHi[axis] - blockLo[axis]);
          for (std::int64_t i = inLo[axis]; i < inHi[axis]; ++i)
            profile[std::size_t(i - cellLo[axis])] += perCell;
        }
    return profile;
  }

  const GridGeometry& grid_;
  SplitAxisRule rule_;
  const ContentGrid* content_;
  std::vector<KdNode>& nodes_;
  std::vector<int>& leafOfRank_;
  Feasibility feasibility_;
};

}  // namespace

KdTree KdTree::make(const GridGeometry& grid, int ranks, SplitAxisRule rule,
                    const ContentGrid* content) {
  grid.validate("k-d tree");
  if (content) checkContentGrid(*content, grid);
  if (ranks < 1)
    throw Error(ErrorCode::kInvalidArgument,
                "k-d tree: rank count is " + std::to_string(ranks) + ", must be >= 1");
  KdTree tree;
  tree.grid_ = grid;
  tree.ranks_ = ranks;
  TreeBuilder(tree.grid_, rule, content, tree.nodes_, tree.leafOfRank_).build(ranks);
  return tree;
}

KdTree KdTree::build(const GridGeometry& grid, int ranks, SplitAxisRule rule) {
  return make(grid, ranks, rule, nullptr);
}

KdTree KdTree::buildBalanced(const GridGeometry& grid, int ranks, SplitAxisRule rule,
                             const ContentGrid& content) {
  return make(grid, ranks, rule, &content);
}

bool KdTree::leftInFront(int node, const Camera& camera) const {
  const KdNode& n = nodes_.at(std::size_t(node));
  if (n.leaf()) return true;
  const int a = n.axis;
  // Perspective: rays leave the eye, so the eye's side is met first (an eye
  // on the plane sees each side through rays that never cross it).
  if (camera.projection() == Projection::kPerspective)
    return !(camera.spec().eye[a] > grid_.origin[a] + double(n.plane) * grid_.spacing[a]);
  // Orthographic: parallel rays all cross the plane the same way.
  return !(camera.forward()[a] < 0);
}

std::vector<int> KdTree::visibilityOrder(const Camera& camera) const {
  // Front-to-back BSP traversal: the front child's leaves, then the back's.
  std::vector<int> order;
  order.reserve(std::size_t(ranks_));
  std::vector<int> stack{root()};
  while (!stack.empty()) {
    const KdNode& n = nodes_[std::size_t(stack.back())];
    const int index = stack.back();
    stack.pop_back();
    if (n.leaf()) {
      order.push_back(n.rankBegin);
      continue;
    }
    const bool leftFirst = leftInFront(index, camera);
    stack.push_back(leftFirst ? n.right : n.left);
    stack.push_back(leftFirst ? n.left : n.right);
  }
  return order;
}

bool KdTree::inFront(int rankA, int rankB, const Camera& camera) const {
  if (rankA < 0 || rankA >= ranks_ || rankB < 0 || rankB >= ranks_)
    throw Error(ErrorCode::kInvalidArgument, "k-d tree: ranks " + std::to_string(rankA) + ", " +
                                                 std::to_string(rankB) + " not in [0, " +
                                                 std::to_string(ranks_) + ")");
  if (rankA == rankB) return false;
  int index = root();
  for (;;) {
    const KdNode& n = nodes_[std::size_t(index)];
    const int middle = nodes_[std::size_t(n.left)].rankEnd;
    const bool aLeft = rankA < middle, bLeft = rankB < middle;
    if (aLeft != bLeft) return aLeft == leftInFront(index, camera);
    index = aLeft ? n.left : n.right;
  }
}

NodeBox storedBox(const KdTree& tree, int rank, int ghost) {
  if (rank < 0 || rank >= tree.rankCount() || ghost < 0)
    throw Error(ErrorCode::kInvalidArgument, "k-d tree: stored box of rank " +
                                                 std::to_string(rank) + " with " +
                                                 std::to_string(ghost) + " ghost layers");
  return tree.ownedBox(rank).grown(ghost).intersect(tree.grid().allNodes());
}

}  // namespace pvr::core
