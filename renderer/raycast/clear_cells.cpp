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

inline void orInto(std::vector<std::uint64_t>& bits, std::int64_t word, std::uint64_t value) {
  if (value) __atomic_fetch_or(&bits[std::size_t(word)], value, __ATOMIC_RELAXED);
}

template <typename T>
void buildTyped(const ClearEnds& ends, const KernelParams& p, std::vector<std::uint64_t>& bits, ThreadPool* pool) {
  const T* v = static_cast<const T*>(p.voxels);
  // nodeClass of every value of T (8 or 16 bits), by its offset from the least.
  constexpr std::int64_t kLeast = std::numeric_limits<T>::min();
  std::vector<std::uint8_t> classOf(std::size_t(1) << (8 * sizeof(T)));
  for (std::size_t n = 0; n < classOf.size(); ++n) classOf[n] = nodeClass(T(kLeast + std::int64_t(n)), ends);
  const std::uint8_t* cls = classOf.data();
  const int i0 = p.storedCellLo[0], j0 = p.storedCellLo[1], k0 = p.storedCellLo[2];
  const std::size_t width = std::size_t(p.storedCellHi[0] - i0 + 2);   // nodes of a row
  const std::size_t height = std::size_t(p.storedCellHi[1] - j0 + 2);  // rows of a plane
  const int planes = p.storedCellHi[2] - k0 + 1;                        // planes of cells
  // A plane of cells from its two planes of nodes: each node classified
  // once a plane (the and of a row's node with its x neighbour, then of a
  // row with the next, then of a plane with the next), so a slab of planes
  // costs a table look-up a node.
  auto squares = [&](int k, std::vector<std::uint8_t>& out) {  // the and of each 2x2 of nodes of plane k
    // Locals, not the lambda's captures: the byte stores below may alias
    // anything, so captured values would be loaded again at every store.
    const std::size_t n = width;
    std::vector<std::uint8_t> rows(2 * n);
    std::uint8_t* row = rows.data();
    std::uint8_t* previous = row + n;
    const std::uint8_t* classes = cls;
    for (std::size_t j = 0; j < height; ++j) {
      const T* nodes = v + (p.base + i0 + std::int64_t(j0 + std::int64_t(j)) * p.strideY + std::int64_t(k) * p.strideZ);
      for (std::size_t i = 0; i < n; ++i) row[i] = classes[std::int64_t(nodes[i]) - kLeast];
      for (std::size_t i = 0; i + 1 < n; ++i) row[i] &= row[i + 1];
      if (j > 0) {
        std::uint8_t* square = out.data() + (j - 1) * n;
        for (std::size_t i = 0; i + 1 < n; ++i) square[i] = previous[i] & row[i];
      }
      std::swap(row, previous);
    }
  };
  // Slabs of planes over the pool; a word of bits two slabs share is or-ed
  // in atomically.
  const int slabs = std::max(1, std::min(planes, 64));
  auto slab = [&](int first, int end) {
    std::vector<std::uint8_t> below(width * height), above(width * height);
    squares(k0 + first, below);
    for (int k = k0 + first; k < k0 + end; ++k) {
      squares(k + 1, above);
      for (std::size_t j = 0; j + 1 < height; ++j) {
        const std::int64_t row = p.base + i0 + std::int64_t(j0 + std::int64_t(j)) * p.strideY + std::int64_t(k) * p.strideZ;
        const std::uint8_t* a = &below[j * width];
        const std::uint8_t* b = &above[j * width];
        // The row's bits gathered a 64-bit word at a time, without a branch
        // on the cells (which are clear and which not is not predictable).
        std::uint64_t word = 0;
        std::int64_t at = row;  // the bit of cell i
        for (std::size_t i = 0; i + 1 < width; ++i, ++at) {
          word |= std::uint64_t((a[i] & b[i]) != 0) << (at & 63);
          if ((at & 63) == 63) {
            orInto(bits, at >> 6, word);
            word = 0;
          }
        }
        orInto(bits, (at - 1) >> 6, word);
      }
      std::swap(below, above);
    }
  };
  auto run = [&](std::size_t n) { slab(int(std::int64_t(planes) * std::int64_t(n) / slabs),
                                       int(std::int64_t(planes) * std::int64_t(n + 1) / slabs)); };
  if (pool)
    pool->parallelFor(std::size_t(slabs), [&](std::size_t n, int) { run(n); });
  else
    for (int n = 0; n < slabs; ++n) run(std::size_t(n));
}

}  // namespace

ClearEnds ClearEnds::ofSamples(const KernelParams& p) { return {p.tableScale, p.tableOffset, p.clearBelow, p.clearAbove}; }

ClearEnds ClearEnds::ofSegments(const PreintegralTables& t) {
  // Infinite ends (none, or every coordinate) as the finite bounds plain
  // tables use.
  if (segmentsClearEnd(t) == EmptyEnd::kLow) return {t.scale, t.offset, std::min(t.clearBelow, FLT_MAX), FLT_MAX};
  return {t.scale, t.offset, -FLT_MAX, std::min(t.clearAbove, FLT_MAX)};
}

void ClearCells::build(const ClearEnds& ends, const KernelParams& p, const Brick& brick, ThreadPool* pool) {
  bits_.clear();
  const IVec3 extents = brick.stored().extents();
  const bool cells = extents.x > 1 && extents.y > 1 && extents.z > 1;
  // (A table's coordinates start at 0: a low end at or below 0 marks nothing.)
  const bool transparentEnd = ends.below > 0 || ends.above < FLT_MAX;
  if (!cells || !transparentEnd || !p.indices32 || brick.type() == ScalarType::kFloat32) return;
  // A bit a node, and 4 bytes more: broadcastWords8 reads 4 from a lane's byte on.
  bits_.assign(std::size_t(brick.stored().nodeCount() / 64 + 2), 0);
  switch (brick.type()) {
    case ScalarType::kUInt8: buildTyped<std::uint8_t>(ends, p, bits_, pool); break;
    case ScalarType::kUInt16: buildTyped<std::uint16_t>(ends, p, bits_, pool); break;
    case ScalarType::kInt16: buildTyped<std::int16_t>(ends, p, bits_, pool); break;
    case ScalarType::kFloat32: break;
  }
}

}  // namespace pvr::core
