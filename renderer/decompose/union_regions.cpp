#include "union_regions.h"

#include <algorithm>
#include <cmath>

#include "../error.h"

namespace pvr::core {

namespace {

// Narrows box on `axis` to [lo, hi], node indices as doubles (infinite or
// far outside for an unbounded face); empty when they miss the box.
void clipAxis(NodeBox& box, int axis, double lo, double hi) {
  if (lo > double(box.lo[axis])) box.lo[axis] = lo > double(box.hi[axis]) ? box.hi[axis] + 1 : std::int64_t(lo);
  if (hi < double(box.hi[axis])) box.hi[axis] = hi < double(box.lo[axis]) ? box.lo[axis] - 1 : std::int64_t(hi);
}

}  // namespace

GridGeometry unionGrid(const std::vector<GridGeometry>& grids) {
  if (grids.empty()) throw Error(ErrorCode::kInvalidArgument, "unionGrid: no volumes");
  Vec3 lo = grids.front().domainMin(), hi = grids.front().domainMax(), spacing = grids.front().spacing;
  for (const GridGeometry& g : grids)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], g.domainMin()[a]);
      hi[a] = std::max(hi[a], g.domainMax()[a]);
      spacing[a] = std::min(spacing[a], g.spacing[a]);
    }
  GridGeometry out;
  out.origin = lo;
  for (int a = 0; a < 3; ++a) {
    const double cells = std::ceil((hi[a] - lo[a]) / spacing[a] - 1e-9);
    // A one-node-thick union stays one node; the node count stays an int
    // a k-d tree can handle whatever spacing a volume has.
    out.dims[a] = std::int64_t(std::clamp(cells, 0.0, double(1 << 30))) + 1;
    out.spacing[a] = out.dims[a] > 1 ? (hi[a] - lo[a]) / double(out.dims[a] - 1) : spacing[a];
  }
  return out;
}

WorldRegion regionOf(const KdTree& tree, int rank) {
  const NodeBox& box = tree.ownedBox(rank);
  const GridGeometry& grid = tree.grid();
  const Vec3 lo = grid.nodePosition(box.lo), hi = grid.nodePosition(box.hi);
  WorldRegion r;
  for (int a = 0; a < 3; ++a) {
    if (box.lo[a] > 0) r.lo[a] = lo[a];
    if (box.hi[a] < grid.dims[a] - 1) r.hi[a] = hi[a];
  }
  return r;
}

NodeBox volumeBoxFor(const GridGeometry& grid, const WorldRegion& region, double step) {
  constexpr std::int64_t kLayers = 3;
  NodeBox box = grid.allNodes();
  for (int a = 0; a < 3; ++a) {
    const double reach = step / grid.spacing[a];
    // In doubles first: an infinite face keeps the grid's own end.
    const double lo = std::floor((region.lo[a] - grid.origin[a]) / grid.spacing[a] - reach) - double(kLayers);
    const double hi = std::ceil((region.hi[a] - grid.origin[a]) / grid.spacing[a] + reach) + double(kLayers);
    clipAxis(box, a, lo, hi);
  }
  return box;
}

NodeBox nodesIn(const GridGeometry& grid, const WorldRegion& region) {
  NodeBox box = grid.allNodes();
  for (int a = 0; a < 3; ++a) {
    // Node n lies in [lo, hi) when ceil(lo) <= n <= ceil(hi) - 1 in index units.
    const double lo = std::ceil((region.lo[a] - grid.origin[a]) / grid.spacing[a]);
    const double hi = std::ceil((region.hi[a] - grid.origin[a]) / grid.spacing[a]) - 1;
    clipAxis(box, a, lo, hi);
  }
  return box;
}

}  // namespace pvr::core
