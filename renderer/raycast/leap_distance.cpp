#include "leap_distance.h"

#include <algorithm>
#include <cstring>
#include <vector>

#include "../thread_pool.h"
#include "macrocells.h"

namespace pvr::core {

namespace {

constexpr std::uint8_t kNear = kLeapNear;
constexpr std::int64_t kPad = kLeapNear - 1;  // rows a window reaches beyond its centre

// Which way a window reaches along its axis: both ways (the cube around a
// macrocell), or forward only, towards higher or lower indices (the box a
// ray of one direction octant leaps, forwardLeapDistance).
enum class Reach { kBoth, kUp, kDown };
constexpr int kBothWays = -1;  // leapField's octant for the cube

// One row of the windowed min-max transform, capped at kNear:
//   out[w] = min over |r| < kNear of max(|r|, centre[w + r * pitch]),
// r >= 0 only (r <= 0) when the window reaches up (down) alone.
// Offsets of kNear or more cannot bring anything below the cap. The rows
// around `centre` are a padded copy (no aliasing with out), so the loops
// vectorise across w.
void windowRow(const std::uint8_t* __restrict centre, std::ptrdiff_t pitch, std::uint8_t* __restrict out,
               std::int64_t width, Reach reach) {
  std::memcpy(out, centre, std::size_t(width));
  if (reach != Reach::kBoth) {
    const std::ptrdiff_t ahead = reach == Reach::kUp ? pitch : -pitch;
    for (int r = 1; r < kNear; ++r) {
      const std::uint8_t* __restrict after = centre + r * ahead;
      const std::uint8_t far = std::uint8_t(r);
      for (std::int64_t w = 0; w < width; ++w) out[w] = std::min(out[w], std::max(far, after[w]));
    }
    return;
  }
  for (int r = 1; r < kNear; ++r) {
    const std::uint8_t* __restrict before = centre - r * pitch;
    const std::uint8_t* __restrict after = centre + r * pitch;
    const std::uint8_t far = std::uint8_t(r);
    for (std::int64_t w = 0; w < width; ++w)
      out[w] = std::min(out[w], std::max(far, std::min(before[w], after[w])));
  }
}

// A padded copy of n rows of `width` bytes (row i at rows[i * step]), kPad
// rows of kNear (nothing near) on either side, so windows need no edges.
class PaddedRows {
 public:
  const std::uint8_t* centre(std::int64_t i) const { return data_.data() + (i + kPad) * width_; }

  void load(const std::uint8_t* rows, std::ptrdiff_t step, std::int64_t n, std::int64_t width) {
    width_ = width;
    data_.assign(std::size_t((n + 2 * kPad) * width), kNear);
    for (std::int64_t i = 0; i < n; ++i)
      std::memcpy(data_.data() + (i + kPad) * width, rows + i * step, std::size_t(width));
  }

 private:
  std::vector<std::uint8_t> data_;
  std::int64_t width_ = 0;
};

// The windowed transform along an axis whose elements lie `step` apart,
// whole rows of `width` at once: for each o < outer, the n rows starting
// at d + o * outerStep.
void windowAcrossRows(std::uint8_t* d, std::int64_t outer, std::ptrdiff_t outerStep, std::ptrdiff_t step,
                      std::int64_t n, std::int64_t width, Reach reach, ThreadPool* pool) {
  forChunks(std::size_t(outer), pool, [&](std::size_t b, std::size_t e) {
    PaddedRows rows;
    for (std::int64_t o = std::int64_t(b); o < std::int64_t(e); ++o) {
      std::uint8_t* base = d + o * outerStep;
      rows.load(base, step, n, width);
      for (std::int64_t i = 0; i < n; ++i) windowRow(rows.centre(i), width, base + i * step, width, reach);
    }
  });
}

// Axis a's reach for `octant` (kBothWays: the cube).
Reach reachOf(int octant, int a) {
  if (octant == kBothWays) return Reach::kBoth;
  return (octant >> a & 1) ? Reach::kDown : Reach::kUp;
}

// The exact capped chessboard distance: the 1-D transform along x, then
// along y, then along z (a cube, or a box reaching forward, is the product
// of three intervals, and capping after each pass gives the capped whole).
void nearDistance(std::uint8_t* d, IVec3 n, int octant, ThreadPool* pool) {
  const std::int64_t nx = n.x, ny = n.y, nz = n.z, layer = nx * ny;
  // Along x: each row padded by kPad elements of kNear on both sides, its
  // empty macrocells (any non-zero) taken as kNear.
  forChunks(std::size_t(ny * nz), pool, [&](std::size_t b, std::size_t e) {
    std::vector<std::uint8_t> row(std::size_t(nx + 2 * kPad), kNear);
    for (std::size_t r = b; r < e; ++r) {
      std::uint8_t* line = d + std::int64_t(r) * nx;
      for (std::int64_t x = 0; x < nx; ++x) row[std::size_t(kPad + x)] = line[x] == 0 ? 0 : kNear;
      windowRow(row.data() + kPad, 1, line, nx, reachOf(octant, 0));
    }
  });
  // Along y, a layer at a time; along z, a column of rows (one per z) at a
  // time: whole rows of x side by side.
  windowAcrossRows(d, nz, layer, nx, ny, nx, reachOf(octant, 1), pool);
  windowAcrossRows(d, ny, nx, layer, nz, nx, reachOf(octant, 2), pool);
}

std::int64_t blocks(std::int64_t cells) { return (cells + kLeapBlock - 1) / kLeapBlock; }

// leapDistance, or forwardLeapDistance for `octant`.
void leapField(std::uint8_t* d, IVec3 n, int octant, ThreadPool* pool) {
  const std::int64_t nx = n.x, ny = n.y, nz = n.z;
  const IVec3 coarseCount{int(blocks(nx)), int(blocks(ny)), int(blocks(nz))};
  const std::int64_t cx = coarseCount.x, cy = coarseCount.y;
  // The coarse grid: a block is visible (0) when any of its macrocells is.
  std::vector<std::uint8_t> coarse(std::size_t(coarseCount.product()), 255);
  forChunks(std::size_t(coarseCount.z), pool, [&](std::size_t b, std::size_t e) {
    for (std::int64_t z = std::int64_t(b) * kLeapBlock; z < std::min(nz, std::int64_t(e) * kLeapBlock); ++z)
      for (std::int64_t y = 0; y < ny; ++y) {
        const std::uint8_t* row = d + (z * ny + y) * nx;
        std::uint8_t* out = coarse.data() + ((z / kLeapBlock) * cy + y / kLeapBlock) * cx;
        for (std::int64_t bx = 0; bx < cx; ++bx) {
          const std::int64_t x0 = bx * kLeapBlock, x1 = std::min(nx, x0 + kLeapBlock);
          if (std::find(row + x0, row + x1, std::uint8_t(0)) != row + x1) out[bx] = 0;
        }
      }
  });
  chessboardDistance(coarse.data(), coarseCount, pool);
  nearDistance(d, n, octant, pool);
  // Beyond the exact range, the coarse bound kBlock (D - 1) + 1 (at least
  // kNear; D >= 1 there: a block with something visible is all near).
  std::uint8_t farBound[256];
  for (int D = 0; D < 256; ++D) farBound[D] = std::uint8_t(std::clamp(kLeapBlock * (D - 1) + 1, int(kNear), 255));
  // Each row takes its bounds from a row of them per x, remade when the
  // row enters another row of blocks; the select then runs across the row.
  forChunks(std::size_t(nz), pool, [&](std::size_t b, std::size_t e) {
    std::vector<std::uint8_t> farRow(static_cast<std::size_t>(nx));
    std::int64_t farOf = -1;  // the block row farRow holds
    for (std::int64_t z = std::int64_t(b); z < std::int64_t(e); ++z)
      for (std::int64_t y = 0; y < ny; ++y) {
        if (const std::int64_t blockRow = (z / kLeapBlock) * cy + y / kLeapBlock; blockRow != farOf) {
          for (std::int64_t x = 0; x < nx; ++x) farRow[std::size_t(x)] = farBound[coarse[std::size_t(blockRow * cx + x / kLeapBlock)]];
          farOf = blockRow;
        }
        std::uint8_t* __restrict row = d + (z * ny + y) * nx;
        const std::uint8_t* __restrict bound = farRow.data();
        for (std::int64_t x = 0; x < nx; ++x) row[x] = row[x] >= kNear ? bound[x] : row[x];
      }
  });
}

}  // namespace

void leapDistance(std::uint8_t* d, IVec3 n, ThreadPool* pool) { leapField(d, n, kBothWays, pool); }

void forwardLeapDistance(std::uint8_t* d, IVec3 n, int octant, ThreadPool* pool) { leapField(d, n, octant, pool); }

}  // namespace pvr::core
