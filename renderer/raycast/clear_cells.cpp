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

// Ors `value` into a word of `bits`, atomically where another thread may
// be writing that word (`shared`).
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

// The bits of a brick's stored cells, by blocks of kSize^3 cells aligned
// as macrocells are. A block that is one of the brick's macrocells, all of
// whose stored cells the brick owns, takes its class from the macrocell's
// node bounds (macrocell_bounds.h): the ends are half-lines of values (the
// table coordinate is linear in the value), so its nodes all lie in one
// end when the least and the greatest both do, and none does when neither
// does. Every other block (ghost cells, no bounds) is read node by node.
// A plane of blocks is independent of the others (plane()).
template <typename T>
class BlockBits {
 public:
  static constexpr int kShift = MacrocellLayout::kShift, kSize = MacrocellLayout::kSize;

  BlockBits(const ClearEnds& ends, const KernelParams& p, const MacrocellBounds* bounds,
            std::vector<std::uint64_t>& bits)
      : p_(p), bounds_(bounds), bits_(bits), classOf_(std::size_t(1) << (8 * sizeof(T))) {
    for (std::size_t n = 0; n < classOf_.size(); ++n) classOf_[n] = nodeClass(T(kLeast + std::int64_t(n)), ends);
    for (int a = 0; a < 3; ++a) {
      lo_[a] = p.storedCellLo[a];
      hi_[a] = p.storedCellHi[a];
      firstBlock_[a] = lo_[a] >> kShift;
      blocks_[a] = (hi_[a] >> kShift) - firstBlock_[a] + 1;
    }
    width_ = hi_[0] - lo_[0] + 1;
    words_ = std::size_t(width_ + 63) / 64;
  }

  int firstPlane() const { return firstBlock_[2]; }
  int planes() const { return blocks_[2]; }

  // The blocks of plane bz, a row of blocks at a time: the bits of its
  // kSize^2 rows of cells gathered in a buffer, then or-ed into the
  // brick's. A row of blocks none of which has a clear cell costs its
  // blocks' bounds alone.
  void plane(int bz) const {
    Scratch s;
    s.rows.resize(words_ * kSize * kSize);
    s.allClear.resize(words_);
    s.row.resize(std::size_t(blocks_[0]));
    int z0, z1, y0, y1;
    cellsOf(2, bz, z0, z1);
    for (int by = firstBlock_[1]; by < firstBlock_[1] + blocks_[1]; ++by) {
      cellsOf(1, by, y0, y1);
      bool any = false;
      for (int n = 0; n < blocks_[0]; ++n) {
        s.row[std::size_t(n)] = blockOf(firstBlock_[0] + n, by, bz);
        any |= s.row[std::size_t(n)] != Block::kNoneClear;
      }
      if (!any) continue;
      markAllClear(s);
      readBlocks(s, y0, y1, z0, z1);
      for (int z = z0; z <= z1; ++z)
        for (int y = y0; y <= y1; ++y)
          orRow(bits_, p_.base + lo_[0] + std::int64_t(y) * p_.strideY + std::int64_t(z) * p_.strideZ,
                &s.rows[rowOf(y, z) * words_], width_);
    }
  }

 private:
  static constexpr std::int64_t kLeast = std::numeric_limits<T>::min();

  // A row of blocks' bits and what it takes to make them.
  struct NodeMasks {
    std::uint32_t low[kSize + 1][kSize + 1], high[kSize + 1][kSize + 1];
  };
  struct Scratch {
    std::vector<std::uint64_t> rows;      // kSize^2 rows of cells' bits (rowOf)
    std::vector<std::uint64_t> allClear;  // a row's cells in blocks Block::kAllClear
    std::vector<Block> row;               // the row's blocks
    std::vector<int> reads;               // those read node by node
    std::vector<NodeMasks> masks;         // their nodes
  };

  std::uint8_t classOfValue(T value) const { return classOf_[std::size_t(std::int64_t(value) - kLeast)]; }

  // The buffer row of cell row (y, z) within its row of blocks.
  static std::size_t rowOf(int y, int z) { return std::size_t((z & (kSize - 1)) * kSize + (y & (kSize - 1))); }

  // The stored cells [c0, c1] of block b along axis a.
  void cellsOf(int a, int b, int& c0, int& c1) const {
    c0 = std::max(lo_[a], b * kSize);
    c1 = std::min(hi_[a], b * kSize + kSize - 1);
  }
  // The same for the row's block n along x.
  void cellsAlongX(int n, int& x0, int& x1) const { cellsOf(0, firstBlock_[0] + n, x0, x1); }

  // The macrocells are p_'s (setBrick: mcFirst, mcCount), of which bounds_
  // holds the bounds.
  Block blockOf(int bx, int by, int bz) const {
    if (!bounds_) return Block::kRead;
    const int b[3] = {bx, by, bz};
    for (int a = 0; a < 3; ++a) {
      int c0, c1;
      cellsOf(a, b[a], c0, c1);
      const bool macrocell = b[a] >= p_.mcFirst[a] && b[a] < p_.mcFirst[a] + p_.mcCount[a];
      if (!macrocell || c0 < p_.ownCellLo[a] || c1 > p_.ownCellHi[a]) return Block::kRead;
    }
    const std::size_t index = kernel::macrocellIndex(p_, b);
    const std::uint8_t least = classOfValue(bounds_->min<T>()[index]);
    const std::uint8_t greatest = classOfValue(bounds_->max<T>()[index]);
    return (least & greatest) ? Block::kAllClear : (least | greatest) ? Block::kRead : Block::kNoneClear;
  }

  // Every buffer row starts as the cells of the row's blocks that are
  // clear whole.
  void markAllClear(Scratch& s) const {
    std::fill(s.allClear.begin(), s.allClear.end(), 0);
    for (int n = 0; n < blocks_[0]; ++n) {
      if (s.row[std::size_t(n)] != Block::kAllClear) continue;
      int x0, x1;
      cellsAlongX(n, x0, x1);
      setCells(s.allClear.data(), x0 - lo_[0], (std::uint64_t(1) << (x1 - x0 + 1)) - 1);
    }
    for (int r = 0; r < kSize * kSize; ++r)
      std::copy(s.allClear.begin(), s.allClear.end(), s.rows.begin() + std::ptrdiff_t(std::size_t(r) * words_));
  }

  // The cells of the blocks read node by node: a row of a block's nodes
  // as two masks (bit x: node x0 + x lies in the low end, in the high
  // end), taken a row of nodes across every such block at a time, so that
  // the reads run forwards through memory; a cell is clear when its eight
  // nodes share an end.
  void readBlocks(Scratch& s, int y0, int y1, int z0, int z1) const {
    s.reads.clear();
    for (int n = 0; n < blocks_[0]; ++n)
      if (s.row[std::size_t(n)] == Block::kRead) s.reads.push_back(n);
    s.masks.resize(s.reads.size());
    const T* v = static_cast<const T*>(p_.voxels);
    for (int z = z0; z <= z1 + 1; ++z)
      for (int y = y0; y <= y1 + 1; ++y) {
        const T* nodes = v + (p_.base + std::int64_t(y) * p_.strideY + std::int64_t(z) * p_.strideZ);
        for (std::size_t r = 0; r < s.reads.size(); ++r) {
          int x0, x1;
          cellsAlongX(s.reads[r], x0, x1);
          std::uint32_t l = 0, h = 0;
          for (int x = 0; x <= x1 - x0 + 1; ++x) {
            const std::uint32_t c = classOfValue(nodes[x0 + x]);
            l |= (c & 1u) << x;
            h |= (c >> 1) << x;
          }
          s.masks[r].low[z - z0][y - y0] = l;
          s.masks[r].high[z - z0][y - y0] = h;
        }
      }
    for (std::size_t r = 0; r < s.reads.size(); ++r) {
      int x0, x1;
      cellsAlongX(s.reads[r], x0, x1);
      const NodeMasks& m = s.masks[r];
      const std::uint32_t cellsOfRow = (1u << (x1 - x0 + 1)) - 1;
      for (int z = 0; z <= z1 - z0; ++z)
        for (int y = 0; y <= y1 - y0; ++y) {
          const std::uint32_t l = m.low[z][y] & m.low[z][y + 1] & m.low[z + 1][y] & m.low[z + 1][y + 1];
          const std::uint32_t h = m.high[z][y] & m.high[z][y + 1] & m.high[z + 1][y] & m.high[z + 1][y + 1];
          setCells(&s.rows[rowOf(y0 + y, z0 + z) * words_], x0 - lo_[0],
                   ((l & (l >> 1)) | (h & (h >> 1))) & cellsOfRow);
        }
    }
  }

  const KernelParams& p_;
  const MacrocellBounds* bounds_;
  std::vector<std::uint64_t>& bits_;
  std::vector<std::uint8_t> classOf_;  // nodeClass of every value of T, by its offset from the least
  int lo_[3], hi_[3];                  // the stored cells
  int firstBlock_[3], blocks_[3];
  int width_;                          // cells of a row
  std::size_t words_;                  // 64-bit words of a buffer row
};

template <typename T>
void buildTyped(const ClearEnds& ends, const KernelParams& p, const MacrocellBounds* bounds,
                std::vector<std::uint64_t>& bits, ThreadPool* pool) {
  const BlockBits<T> blocks(ends, p, bounds, bits);
  if (pool)
    pool->parallelFor(std::size_t(blocks.planes()), [&](std::size_t n, int) { blocks.plane(blocks.firstPlane() + int(n)); });
  else
    for (int n = 0; n < blocks.planes(); ++n) blocks.plane(blocks.firstPlane() + n);
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
  const bool small = brick.stored().nodeCount() <= kMaxNodes;
  if (!cells || !transparentEnd || !small || !p.indices32 || brick.type() == ScalarType::kFloat32) {
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
