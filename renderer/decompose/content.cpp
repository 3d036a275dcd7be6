#include "content.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "../error.h"
#include "../thread_pool.h"

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

namespace {

// Whether the transfer function shows a voxel of value v; for 8- and 16-bit
// data one table look-up per voxel, built from TransferTable::anyVisible.
template <typename T>
class VisibleValues {
 public:
  explicit VisibleValues(const TransferTable& table) : table_(table) {
    if constexpr (!std::is_floating_point_v<T>) {
      const int lo = std::numeric_limits<T>::lowest(), hi = std::numeric_limits<T>::max();
      lut_.resize(std::size_t(hi - lo + 1));
      for (int v = lo; v <= hi; ++v) lut_[std::size_t(v - lo)] = table.anyVisible(v, v);
    }
  }
  std::uint32_t operator()(T v) const {
    if constexpr (std::is_floating_point_v<T>)
      return std::isfinite(v) && table_.anyVisible(double(v), double(v));
    else
      return lut_[std::size_t(int(v) - int(std::numeric_limits<T>::lowest()))];
  }

 private:
  const TransferTable& table_;
  std::vector<std::uint8_t> lut_;
};

}  // namespace

ContentGrid countContent(const Brick& brick, const TransferTable& table, IVec3 blockCells,
                         ThreadPool* pool) {
  const GridGeometry& grid = brick.grid();
  ContentGrid c = makeContentGrid(grid, blockCells);

  // The nodes this brick owns half-open, and the block of each.
  const NodeBox& own = brick.owned();
  IVec3 end;  // one past the last counted node per axis
  for (int a = 0; a < 3; ++a) end[a] = own.hi[a] == grid.dims[a] - 1 ? own.hi[a] + 1 : own.hi[a];
  auto blockOf = [&](int a, std::int64_t n) {
    return std::min(n / c.blockCells[a], c.blocks[a] - 1);
  };
  // Where block bx's nodes end on x within [own.lo.x, end.x).
  auto blockEndX = [&](std::int64_t bx) {
    return bx == c.blocks.x - 1 ? end.x : std::min(end.x, (bx + 1) * c.blockCells.x);
  };

  dispatchScalar(brick.type(), [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    const T* v = brick.as<T>();
    const VisibleValues<T> shows(table);
    // Layers of blocks go to threads whole, so each count has one writer.
    const std::int64_t bz0 = blockOf(2, own.lo.z), bz1 = blockOf(2, end.z - 1);
    auto countLayers = [&](std::int64_t b0, std::int64_t b1) {
      const std::int64_t z0 = std::max(own.lo.z, b0 * c.blockCells.z);
      const std::int64_t z1 = b1 > bz1 ? end.z : std::min(end.z, b1 * c.blockCells.z);
      for (std::int64_t z = z0; z < z1; ++z)
        for (std::int64_t y = own.lo.y; y < end.y; ++y) {
          std::uint64_t* rowBlocks =
              c.counts.data() + std::size_t((blockOf(2, z) * c.blocks.y + blockOf(1, y)) * c.blocks.x);
          const T* row = v + brick.linearIndex({own.lo.x, y, z});  // row[i] is node own.lo.x + i
          for (std::int64_t bx = blockOf(0, own.lo.x); bx <= blockOf(0, end.x - 1); ++bx) {
            std::uint32_t n = 0;
            const std::int64_t xa = std::max(own.lo.x, bx * c.blockCells.x) - own.lo.x;
            const std::int64_t xe = blockEndX(bx) - own.lo.x;
            for (std::int64_t x = xa; x < xe; ++x) n += shows(row[x]);
            rowBlocks[bx] += n;
          }
        }
    };
    const std::size_t layers = std::size_t(bz1 - bz0 + 1);
    const std::size_t chunks = pool ? std::min<std::size_t>(layers, std::size_t(pool->size()) * 4) : 1;
    if (chunks <= 1) {
      countLayers(bz0, bz1 + 1);
    } else {
      pool->parallelFor(chunks, [&](std::size_t k, int) {
        countLayers(bz0 + std::int64_t(layers * k / chunks), bz0 + std::int64_t(layers * (k + 1) / chunks));
      });
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
