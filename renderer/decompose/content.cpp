#include "content.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>

#include "../error.h"

namespace pvr::core {

namespace {

std::string shapeText(const ContentGrid& c) {
  return std::to_string(c.blocks.x) + "x" + std::to_string(c.blocks.y) + "x" +
         std::to_string(c.blocks.z) + " blocks of " + std::to_string(c.blockCells.x) + "x" +
         std::to_string(c.blockCells.y) + "x" + std::to_string(c.blockCells.z) + " cells";
}

}  // namespace

ContentGrid makeContentGrid(const GridGeometry& grid, IVec3 blockCells) {
  ContentGrid c;
  c.blockCells = blockCells;
  for (int a = 0; a < 3; ++a) {
    if (blockCells[a] < 1)
      throw Error(ErrorCode::kInvalidArgument, "content grid: block edge " + std::to_string(a) +
                                                   " is " + std::to_string(blockCells[a]) +
                                                   " cells, must be >= 1");
    const std::int64_t cells = grid.dims[a] - 1;
    c.blocks[a] = std::max<std::int64_t>(1, (cells + blockCells[a] - 1) / blockCells[a]);
  }
  c.counts.assign(std::size_t(c.blocks.product()), 0);
  return c;
}

ContentGrid countContent(const Brick& brick, const TransferTable& table, IVec3 blockCells) {
  const GridGeometry& grid = brick.grid();
  ContentGrid c = makeContentGrid(grid, blockCells);

  // The nodes this brick owns half-open, and the block of each.
  const NodeBox& own = brick.owned();
  IVec3 end;  // one past the last counted node per axis
  for (int a = 0; a < 3; ++a) end[a] = own.hi[a] == grid.dims[a] - 1 ? own.hi[a] + 1 : own.hi[a];
  auto blockOf = [&](int a, std::int64_t n) {
    return std::min(n / c.blockCells[a], c.blocks[a] - 1);
  };

  dispatchScalar(brick.type(), [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    const T* v = brick.as<T>();
    for (std::int64_t z = own.lo.z; z < end.z; ++z)
      for (std::int64_t y = own.lo.y; y < end.y; ++y) {
        const std::size_t rowBlocks =
            std::size_t((blockOf(2, z) * c.blocks.y + blockOf(1, y)) * c.blocks.x);
        const T* row = v + brick.linearIndex({own.lo.x, y, z});
        for (std::int64_t x = own.lo.x; x < end.x; ++x) {
          const double s = double(row[x - own.lo.x]);
          if (std::isfinite(s) && table.anyVisible(s, s))
            ++c.counts[rowBlocks + std::size_t(blockOf(0, x))];
        }
      }
  });
  return c;
}

void checkContentGrid(const ContentGrid& content, const GridGeometry& grid) {
  for (int a = 0; a < 3; ++a)
    if (content.blockCells[a] < 1)
      throw Error(ErrorCode::kInvalidArgument,
                  "content grid: " + shapeText(content) + " has a block edge < 1");
  const ContentGrid expected = makeContentGrid(grid, content.blockCells);
  if (!(expected.blocks == content.blocks) || content.counts.size() != expected.counts.size())
    throw Error(ErrorCode::kInvalidArgument,
                "content grid: " + shapeText(content) + " with " +
                    std::to_string(content.counts.size()) + " counts does not fit the grid " +
                    toString(grid.allNodes()) + " (needs " + shapeText(expected) + ")");
}

void addContent(ContentGrid& sum, const ContentGrid& part) {
  if (!(sum.blockCells == part.blockCells) || !(sum.blocks == part.blocks) ||
      sum.counts.size() != part.counts.size())
    throw Error(ErrorCode::kInvalidArgument,
                "content grid: cannot add " + shapeText(part) + " to " + shapeText(sum));
  for (std::size_t i = 0; i < sum.counts.size(); ++i) sum.counts[i] += part.counts[i];
}

std::uint64_t totalContent(const ContentGrid& content) {
  std::uint64_t total = 0;
  for (std::uint64_t n : content.counts) total += n;
  return total;
}

}  // namespace pvr::core
