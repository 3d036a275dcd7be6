#include "clear_cells.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>
#include <utility>

#include "kernel.h"

namespace pvr::core {

namespace {

// 1: the node lies in the table's transparent low end, 2: in its high end,
// each with a margin beyond what the reconstruction's rounding can move a
// sample: its three levels of float lerps err by a few ulp of the cell's
// largest magnitude (here, T's: a cell of -30000 and 5 errs near 5 by ulps
// of 30000), the table coordinate's fused multiply-add by half an ulp.
template <typename T>
std::uint8_t nodeClass(T v, const ClearEnds& ends) {
  constexpr double kLargest = std::max(-double(std::numeric_limits<T>::min()), double(std::numeric_limits<T>::max()));
  const double value = double(v);
  const double x = value * double(ends.scale) + double(ends.offset);
  const double margin = std::abs(double(ends.scale)) * kLargest * 0x1p-18 + 0x1p-8;
  return std::uint8_t((x + margin < double(ends.below) ? 1 : 0) | (x - margin >= double(ends.above) ? 2 : 0));
}

inline void orInto(std::vector<std::uint64_t>& bits, std::int64_t word, std::uint64_t value, bool shared) {
  if (!value) return;
  if (shared) __atomic_fetch_or(&bits[std::size_t(word)], value, __ATOMIC_RELAXED);
  else bits[std::size_t(word)] |= value;
}

// Sets the bits of `cells` (bit n: cell at + n) in the row `to`.
inline void setCells(std::uint64_t* to, int at, std::uint64_t cells) {
  to[at >> 6] |= cells << (at & 63);
  const std::uint64_t spill = (at & 63) ? cells >> (64 - (at & 63)) : 0;
  if (spill) to[(at >> 6) + 1] |= spill;
}

// Ors the `width` bits of a row of cells into `bits` from bit `at` on. The
// words strictly inside the row hold its bits alone; its first and last
// may hold another row's, which another thread may be writing, so they are
// or-ed atomically.
inline void orRow(std::vector<std::uint64_t>& bits, std::int64_t at, const std::uint64_t* cells, int width) {
  const std::int64_t first = at >> 6, last = (at + width - 1) >> 6;
  const int shift = int(at & 63);
  for (std::int64_t w = 0; w < (width + 63) / 64; ++w) {
    const std::int64_t word = first + w;
    orInto(bits, word, cells[w] << shift, word == first || word == last);
    if (shift && word + 1 <= last) orInto(bits, word + 1, cells[w] >> (64 - shift), word + 1 == last);
  }
}

// How a block of cells stands against the ends, from its nodes' bounds.
enum class Block : std::uint8_t { kNoneClear, kAllClear, kRead };

template <typename T>
void buildTyped(const ClearEnds& ends, const KernelParams& p, const MacrocellBounds* bounds,
                std::vector<std::uint64_t>& bits, ThreadPool* pool) {
  const T* v = static_cast<const T*>(p.voxels);
  // nodeClass of every value of T (8 or 16 bits), by its offset from the least.
  constexpr std::int64_t kLeast = std::numeric_limits<T>::min();
  std::vector<std::uint8_t> classOf(std::size_t(1) << (8 * sizeof(T)));
  for (std::size_t n = 0; n < classOf.size(); ++n) classOf[n] = nodeClass(T(kLeast + std::int64_t(n)), ends);
  const std::uint8_t* cls = classOf.data();
  auto classOfValue = [cls](T value) { return cls[std::int64_t(value) - kLeast]; };
  constexpr int kShift = MacrocellLayout::kShift, kSize = MacrocellLayout::kSize;
  const int lo[3] = {p.storedCellLo[0], p.storedCellLo[1], p.storedCellLo[2]};
  const int hi[3] = {p.storedCellHi[0], p.storedCellHi[1], p.storedCellHi[2]};
  // Blocks of kSize^3 cells aligned as macrocells are, over the stored cells.
  int firstBlock[3], blocks[3];
  for (int a = 0; a < 3; ++a) {
    firstBlock[a] = lo[a] >> kShift;
    blocks[a] = (hi[a] >> kShift) - firstBlock[a] + 1;
  }
  // A block that is one of the brick's macrocells, all of whose stored
  // cells the brick owns, takes its class from the macrocell's node bounds
  // (macrocell_bounds.h). The ends are half-lines of values (the table
  // coordinate is linear in the value), so the nodes all lie in one end
  // when the least and the greatest both do, and none does when neither
  // does. Every other block (ghost cells, no bounds) is read node by node.
  auto blockOf = [&](int bx, int by, int bz) {
    if (!bounds) return Block::kRead;
    const int b[3] = {bx, by, bz};
    const MacrocellLayout& layout = bounds->layout();
    std::int64_t index = 0;
    for (int a = 2; a >= 0; --a) {
      const std::int64_t m = b[a] - layout.first[a];
      const bool owned = std::max(b[a] * kSize, lo[a]) >= p.ownCellLo[a] &&
                         std::min(b[a] * kSize + kSize - 1, hi[a]) <= p.ownCellHi[a];
      if (m < 0 || m >= layout.count[a] || !owned) return Block::kRead;
      index = index * layout.count[a] + m;
    }
    const std::uint8_t least = classOfValue(bounds->min<T>()[index]);
    const std::uint8_t greatest = classOfValue(bounds->max<T>()[index]);
    return (least & greatest) ? Block::kAllClear : (least | greatest) ? Block::kRead : Block::kNoneClear;
  };
  const int width = hi[0] - lo[0] + 1;  // cells of a row
  const std::size_t words = std::size_t(width + 63) / 64;
  // One plane of blocks: its rows of blocks one by one, the bits of their
  // kSize^2 rows of cells gathered in `rows` and or-ed into `bits` a row
  // at a time (orRow). A row of blocks none of which has a clear cell
  // costs its blocks' bounds alone.
  auto plane = [&](int bz) {
    std::vector<std::uint64_t> rows(words * kSize * kSize), allClear(words);
    std::vector<Block> row(static_cast<std::size_t>(blocks[0]));
    struct NodeMasks {
      std::uint32_t low[kSize + 1][kSize + 1], high[kSize + 1][kSize + 1];
    };
    std::vector<int> reads;  // the row's blocks read node by node
    std::vector<NodeMasks> masks;
    auto cellsOf = [&](int n, int& x0, int& x1) {  // the stored cells of the row's block n along x
      x0 = std::max(lo[0], (firstBlock[0] + n) * kSize);
      x1 = std::min(hi[0], (firstBlock[0] + n) * kSize + kSize - 1);
    };
    const int z0 = std::max(lo[2], bz * kSize), z1 = std::min(hi[2], bz * kSize + kSize - 1);
    for (int by = firstBlock[1]; by < firstBlock[1] + blocks[1]; ++by) {
      const int y0 = std::max(lo[1], by * kSize), y1 = std::min(hi[1], by * kSize + kSize - 1);
      bool any = false;
      for (int n = 0; n < blocks[0]; ++n) {
        row[std::size_t(n)] = blockOf(firstBlock[0] + n, by, bz);
        any |= row[std::size_t(n)] != Block::kNoneClear;
      }
      if (!any) continue;
      std::fill(allClear.begin(), allClear.end(), 0);
      for (int n = 0; n < blocks[0]; ++n) {
        if (row[std::size_t(n)] != Block::kAllClear) continue;
        int x0, x1;
        cellsOf(n, x0, x1);
        setCells(allClear.data(), x0 - lo[0], (std::uint64_t(1) << (x1 - x0 + 1)) - 1);
      }
      for (int r = 0; r < kSize * kSize; ++r)
        std::copy(allClear.begin(), allClear.end(), rows.begin() + std::ptrdiff_t(std::size_t(r) * words));
      // The nodes of the blocks read, a row of a block's nodes as two masks
      // (bit x: node x0 + x lies in the low end, in the high end), taken
      // a row of nodes across every block at a time, so that the reads run
      // forwards through memory; a cell is clear when its eight nodes
      // share an end.
      reads.clear();
      for (int n = 0; n < blocks[0]; ++n)
        if (row[std::size_t(n)] == Block::kRead) reads.push_back(n);
      masks.resize(reads.size());
      for (int z = z0; z <= z1 + 1; ++z)
        for (int y = y0; y <= y1 + 1; ++y) {
          const T* nodes = v + (p.base + std::int64_t(y) * p.strideY + std::int64_t(z) * p.strideZ);
          for (std::size_t r = 0; r < reads.size(); ++r) {
            int x0, x1;
            cellsOf(reads[r], x0, x1);
            std::uint32_t l = 0, h = 0;
            for (int x = 0; x <= x1 - x0 + 1; ++x) {
              const std::uint32_t c = classOfValue(nodes[x0 + x]);
              l |= (c & 1u) << x;
              h |= (c >> 1) << x;
            }
            masks[r].low[z - z0][y - y0] = l;
            masks[r].high[z - z0][y - y0] = h;
          }
        }
      for (std::size_t r = 0; r < reads.size(); ++r) {
        int x0, x1;
        cellsOf(reads[r], x0, x1);
        const NodeMasks& m = masks[r];
        const std::uint32_t cellsOfRow = (1u << (x1 - x0 + 1)) - 1;
        for (int z = 0; z <= z1 - z0; ++z)
          for (int y = 0; y <= y1 - y0; ++y) {
            const std::uint32_t l = m.low[z][y] & m.low[z][y + 1] & m.low[z + 1][y] & m.low[z + 1][y + 1];
            const std::uint32_t h = m.high[z][y] & m.high[z][y + 1] & m.high[z + 1][y] & m.high[z + 1][y + 1];
            const int at = (z0 - bz * kSize + z) * kSize + (y0 - by * kSize + y);
            setCells(rows.data() + std::size_t(at) * words, x0 - lo[0], ((l & (l >> 1)) | (h & (h >> 1))) & cellsOfRow);
          }
      }
      for (int z = z0; z <= z1; ++z)
        for (int y = y0; y <= y1; ++y) {
          const std::uint64_t* cells = rows.data() + std::size_t((z - bz * kSize) * kSize + (y - by * kSize)) * words;
          orRow(bits, p.base + lo[0] + std::int64_t(y) * p.strideY + std::int64_t(z) * p.strideZ, cells, width);
        }
    }
  };
  if (pool)
    pool->parallelFor(std::size_t(blocks[2]), [&](std::size_t n, int) { plane(firstBlock[2] + int(n)); });
  else
    for (int n = 0; n < blocks[2]; ++n) plane(firstBlock[2] + n);
}

}  // namespace

ClearEnds ClearEnds::ofSamples(const KernelParams& p) { return {p.tableScale, p.tableOffset, p.clearBelow, p.clearAbove}; }

ClearEnds ClearEnds::ofSegments(const PreintegralTables& t) {
  // Infinite ends (none, or every coordinate) as the finite bounds plain
  // tables use.
  if (segmentsClearEnd(t) == EmptyEnd::kLow) return {t.scale, t.offset, std::min(t.clearBelow, FLT_MAX), FLT_MAX};
  return {t.scale, t.offset, -FLT_MAX, std::min(t.clearAbove, FLT_MAX)};
}

bool ClearCells::build(const ClearEnds& ends, const KernelParams& p, const Brick& brick,
                       const MacrocellBounds* bounds, ThreadPool* pool) {
  if (builtFor_ == ends) return false;
  builtFor_.reset();  // (until the bits are whole)
  bits_.clear();
  const IVec3 extents = brick.stored().extents();
  const bool cells = extents.x > 1 && extents.y > 1 && extents.z > 1;
  // (A table's coordinates start at 0: a low end at or below 0 marks nothing.)
  const bool transparentEnd = ends.below > 0 || ends.above < FLT_MAX;
  if (!cells || !transparentEnd || !p.indices32 || brick.type() == ScalarType::kFloat32) {
    builtFor_ = ends;
    return true;
  }
  // A bit a node, and 4 bytes more: broadcastWords8 reads 4 from a lane's byte on.
  bits_.assign(std::size_t(brick.stored().nodeCount() / 64 + 2), 0);
  switch (brick.type()) {
    case ScalarType::kUInt8: buildTyped<std::uint8_t>(ends, p, bounds, bits_, pool); break;
    case ScalarType::kUInt16: buildTyped<std::uint16_t>(ends, p, bounds, bits_, pool); break;
    case ScalarType::kInt16: buildTyped<std::int16_t>(ends, p, bounds, bits_, pool); break;
    case ScalarType::kFloat32: break;
  }
  builtFor_ = ends;
  return true;
}

}  // namespace pvr::core
