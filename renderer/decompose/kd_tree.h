// k-d decomposition of the grid over ranks, and visibility order.
//
// The tree splits the grid's cells by axis-aligned planes of nodes; a leaf
// is one rank's brick (its owned NodeBox; neighbours share the plane node).
// Ranks are numbered in tree order (every subtree holds a contiguous range
// of ranks), so compositing strategies can pair ranks by subtree and ask the
// tree which side of a split is nearer the viewer.
#pragma once

#include <cstdint>
#include <vector>

#include "../camera.h"
#include "../grid.h"

namespace pvr::core {

// kAlternating: x, y, z in turn down the tree; kLongest: the region's
// longest side; kSlowest: z (a file's slowest axis) first, then y, then x,
// so bricks are whole slabs, each one run of the file, while the ranks
// leave z cells to split.
enum class SplitAxisRule { kAlternating, kLongest, kSlowest };

struct KdNode {
  NodeBox box;            // nodes of this subtree's region
  int axis = -1;          // split axis; -1 for a leaf
  std::int64_t plane = 0; // split node index: left holds box.lo..plane, right plane..box.hi
  int left = -1, right = -1;  // child node indices
  int rankBegin = 0, rankEnd = 0;  // ranks [rankBegin, rankEnd) of this subtree
  bool leaf() const { return axis < 0; }
};

// Non-empty voxel counts on a coarse grid (one count per macrocell-sized
// block of cells), the input of content balancing.
struct ContentGrid {
  IVec3 blockCells{8, 8, 8};  // cells per block edge
  IVec3 blocks;               // blocks per axis
  std::vector<std::uint64_t> counts;  // x fastest
};

class KdTree {
 public:
  // Splits into `ranks` leaves; a node with n ranks gives floor(n/2) to the
  // left and ceil(n/2) to the right, and places the plane so each side's
  // cell count is proportional to its rank count. Every leaf keeps at least
  // one cell on every axis the grid has cells on; where the proportional
  // plane would starve a side of the cells its ranks need, the plane moves
  // just far enough. Axes: kAlternating takes x, y, z, x, ... (each child
  // starts after its parent's axis) and skips an axis no plane can split;
  // kLongest takes the longest splittable axis in world units (spacing
  // counts; ties go to the lower axis). Throws pvr::Error if ranks < 1 or
  // no such tree exists (e.g. more ranks than cells).
  static KdTree build(const GridGeometry& grid, int ranks, SplitAxisRule rule);
  // As build, but planes split the non-empty content (ContentGrid, see
  // content.h; a block's count is taken as spread evenly over its cells) in
  // proportion to the ranks instead of the cells. A region without content
  // splits by cells. Throws if `content` does not fit the grid.
  static KdTree buildBalanced(const GridGeometry& grid, int ranks, SplitAxisRule rule,
                              const ContentGrid& content);

  int rankCount() const { return ranks_; }
  const std::vector<KdNode>& nodes() const { return nodes_; }
  int root() const { return 0; }
  const NodeBox& ownedBox(int rank) const { return nodes_[leafOfRank_[rank]].box; }
  int leafOfRank(int rank) const { return leafOfRank_[rank]; }

  // True when node's left child is nearer the viewer than its right child
  // (for perspective: the eye's side of the plane; orthographic: the side
  // the view direction comes from). Valid for an eye inside the grid too.
  bool leftInFront(int node, const Camera& camera) const;
  // Ranks front to back for this camera.
  std::vector<int> visibilityOrder(const Camera& camera) const;
  // True when rankA's brick comes before rankB's in visibilityOrder: the
  // split that separates them (their lowest common ancestor) puts rankA on
  // the viewer's side. O(depth); for strategies that pair ranks freely.
  bool inFront(int rankA, int rankB, const Camera& camera) const;

  const GridGeometry& grid() const { return grid_; }

 private:
  // build and buildBalanced; `content` is null for the plain split.
  static KdTree make(const GridGeometry& grid, int ranks, SplitAxisRule rule,
                     const ContentGrid* content);

  GridGeometry grid_;
  int ranks_ = 0;
  std::vector<KdNode> nodes_;
  std::vector<int> leafOfRank_;
};

// The box `rank` stores: its owned box grown by `ghost` layers (from
// ghostLayers() of the render options), clipped to the grid; the stored box
// of cropBrick(source, tree.ownedBox(rank), ghost).
NodeBox storedBox(const KdTree& tree, int rank, int ghost);

}  // namespace pvr::core
