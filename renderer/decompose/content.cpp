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

// Which values the transfer function shows. For float data the table is
// asked per voxel, except in pieces of a row it shows nothing of. For 8-
// and 16-bit data it is asked once per possible value; when the shown values form one
// interval [lo, lo + span] (the usual case) a voxel's test is one unsigned
// compare the compiler vectorises, otherwise one look-up.
template <typename T>
class VisibleValues {
 public:
  explicit VisibleValues(const TransferTable& table) : table_(table) {
    if constexpr (!std::is_floating_point_v<T>) {
      const int lo = std::numeric_limits<T>::lowest(), hi = std::numeric_limits<T>::max();
      lut_.resize(std::size_t(hi - lo + 1));
      int runs = 0, first = 0, last = 0;
      for (int v = lo; v <= hi; ++v) {
        const bool shown = table.anyVisible(v, v);
        lut_[std::size_t(v - lo)] = shown;
        if (shown && (v == lo || !lut_[std::size_t(v - 1 - lo)])) ++runs, first = v;
        if (shown) last = v;
      }
      none_ = runs == 0;
      oneInterval_ = runs == 1;
      lo_ = T(first);
      span_ = U(last - first);
    }
  }
  bool showsNothing() const { return none_; }

  // col[i] += shown(row[i]) for i in [0, n).
  void addRow(const T* row, std::size_t n, std::uint32_t* col) const {
    if constexpr (std::is_floating_point_v<T>) {
      // Pieces whose finite range the table shows nothing of are skipped
      // whole: anyVisible(lo, hi) holds whenever anyVisible(v, v) does for
      // some v in [lo, hi]. The rest ask the table voxel by voxel.
      constexpr std::size_t kPiece = 64;
      for (std::size_t p = 0; p < n; p += kPiece) {
        const std::size_t e = std::min(n, p + kPiece);
        T lo = std::numeric_limits<T>::infinity(), hi = -lo;
        for (std::size_t i = p; i < e; ++i) {
          const bool finite = (row[i] - row[i]) == T(0);
          lo = std::min(lo, finite ? row[i] : lo);
          hi = std::max(hi, finite ? row[i] : hi);
        }
        if (!(lo <= hi) || !table_.anyVisible(double(lo), double(hi))) continue;
        for (std::size_t i = p; i < e; ++i)
          col[i] += std::isfinite(row[i]) && table_.anyVisible(double(row[i]), double(row[i]));
      }
    } else if (oneInterval_) {
      const T lo = lo_;
      const U span = span_;
      for (std::size_t i = 0; i < n; ++i) col[i] += U(U(row[i]) - U(lo)) <= span;
    } else {
      const std::uint8_t* lut = lut_.data();
      for (std::size_t i = 0; i < n; ++i)
        col[i] += lut[std::size_t(int(row[i]) - int(std::numeric_limits<T>::lowest()))];
    }
  }

 private:
  using U = std::make_unsigned_t<std::conditional_t<std::is_floating_point_v<T>, int, T>>;
  const TransferTable& table_;
  std::vector<std::uint8_t> lut_;
  bool none_ = false, oneInterval_ = false;
  T lo_{};
  U span_{};
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
  // The counted nodes of block b on axis a: [blockBegin, blockEnd).
  auto blockBegin = [&](int a, std::int64_t b) { return std::max(own.lo[a], b * c.blockCells[a]); };
  auto blockEnd = [&](int a, std::int64_t b) {
    return b == c.blocks[a] - 1 ? end[a] : std::min(end[a], (b + 1) * c.blockCells[a]);
  };
  const IVec3 firstBlock{blockOf(0, own.lo.x), blockOf(1, own.lo.y), blockOf(2, own.lo.z)};
  const IVec3 lastBlock{blockOf(0, end.x - 1), blockOf(1, end.y - 1), blockOf(2, end.z - 1)};

  dispatchScalar(brick.type(), [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    const T* v = brick.as<T>();
    const VisibleValues<T> shows(table);
    if (shows.showsNothing()) return;
    // Per row of blocks: count each column (x) over the block rows' y and
    // z element by element, then add the columns up per block. Layers of
    // blocks go to threads whole, so each count has one writer.
    const std::size_t nx = std::size_t(end.x - own.lo.x);
    auto countLayers = [&](std::int64_t bz0, std::int64_t bz1) {
      std::vector<std::uint32_t> col(nx);
      for (std::int64_t bz = bz0; bz < bz1; ++bz)
        for (std::int64_t by = firstBlock.y; by <= lastBlock.y; ++by) {
          std::fill(col.begin(), col.end(), 0);
          for (std::int64_t z = blockBegin(2, bz); z < blockEnd(2, bz); ++z)
            for (std::int64_t y = blockBegin(1, by); y < blockEnd(1, by); ++y)
              shows.addRow(v + brick.linearIndex({own.lo.x, y, z}), nx, col.data());
          std::uint64_t* counts = c.counts.data() + std::size_t((bz * c.blocks.y + by) * c.blocks.x);
          for (std::int64_t bx = firstBlock.x; bx <= lastBlock.x; ++bx) {
            std::uint64_t n = 0;
            for (std::int64_t x = blockBegin(0, bx); x < blockEnd(0, bx); ++x) n += col[std::size_t(x - own.lo.x)];
            counts[bx] += n;
          }
        }
    };
    forChunks(std::size_t(lastBlock.z - firstBlock.z + 1), pool, [&](std::size_t b, std::size_t e) {
      countLayers(firstBlock.z + std::int64_t(b), firstBlock.z + std::int64_t(e));
    });
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
