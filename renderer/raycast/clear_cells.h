// Cells every sample of which classifies as transparent, one bit a cell,
// for the batched kernel: a batch whose eight samples all lie in such cells
// is skipped before a voxel is read (kernel_batch.h).
//
// A cell is clear when its eight nodes all lie in the transfer function's
// transparent low end, or all in its transparent high end (KernelParams::
// clearBelow, clearAbove): a trilinear sample lies between its cell's least
// and greatest node, and the table coordinate is monotonic in the value, so
// the sample lies in the same end. Macrocells (4^3 cells) leave many such
// cells where they meet visible data: on the peer scene 38 % of the batches
// in visible chunks were transparent, 31 % with every sample in a clear
// cell; on the CT head 57 % and 46 % (bench/results/plain.txt, section 10).
// The float lerps of the reconstruction may overshoot their ends by an ulp
// or two, so a node counts as clear only with a margin beyond that.
//
// Pre-integrated segments (kernel_batch.h) skip by them too: a segment
// integrates between its end nodes, which are clamped into the range of
// their cells' nodes, so one between two nodes in clear cells of the same
// end integrates nothing. Between the two ends it would cross the visible
// values, so their cells mark one end only (ClearEnds::ofSegments).
//
// Integer voxels only (8 and 16 bits): their differences are exact in
// float, and they have no NaN. The bit of a cell is that of the voxel index
// (KernelParams) of its lowest node: 1/8 byte per stored voxel.
//
// Only for bricks of at most kMaxNodes nodes (2^25, 4 MiB of bits): the
// bits pay while they stay in the caches. Two threads, the CT head
// resampled to n^3 (bench/results/scale/clear_cells.md): no difference at
// 256^3 (2 MiB of bits), 3-4 % slower a frame at 384^3 (6.75 MiB), 11 % at
// 512^3, 15 % at 1024^3, where the bitmap's loads miss as the voxels' do.
// And 1/8 byte a voxel is 12.5 % of a uint8 brick, against issue 11's bound
// of 1.1x a rank's share (a 2048^3 rank on 8 ranks peaks at 1.09x without
// the bits, 1.22x with them); up to 2^25 nodes a rank's own ~28 MiB (MPI,
// the libraries) is over a tenth of its share already.
//
// Built on every transfer-function change, at a cost that follows the
// visible data's surface, not the grid: a macrocell whose node bounds lie
// in one end is marked whole and one with no node in either end is left,
// both without reading a voxel; only the macrocells the ends' boundary
// crosses are read node by node (on the peer scene about a tenth of them,
// on the CT head a sixth).
#pragma once

#include <cfloat>
#include <cstdint>
#include <optional>
#include <vector>

#include "../brick.h"
#include "../macrocell_bounds.h"
#include "../preintegration.h"
#include "../thread_pool.h"

namespace pvr::core {

struct KernelParams;

// The transparent ends a bitmap marks, in table coordinates x = value *
// scale + offset: x < below, or x >= above (FLT_MAX for no high end).
struct ClearEnds {
  float scale = 0, offset = 0;
  float below = -FLT_MAX, above = FLT_MAX;

  bool operator==(const ClearEnds&) const = default;

  // Both ends of p's plain table (KernelParams::clearBelow, clearAbove):
  // each sample is classified on its own.
  static ClearEnds ofSamples(const KernelParams& p);
  // One end of a pre-integrated table (PreintegralTables::clearBelow,
  // clearAbove), the low one where it has one (segmentsClearEnd()).
  static ClearEnds ofSegments(const PreintegralTables& t);
};

class ClearCells {
 public:
  static constexpr std::int64_t kMaxNodes = std::int64_t(1) << 25;  // stored nodes (see above)

  // The cells of `brick`'s stored box (p: setBrick of this brick) whose
  // nodes all lie in one of `ends`; none for a float brick, a box without
  // cells or of more than kMaxNodes nodes, or no transparent end.
  // `bounds`: the brick's macrocell bounds (MacrocellGrid::bounds()), by
  // which whole macrocells are decided without their voxels; null reads
  // every node (the same bits).
  // A ClearCells serves one brick, whose voxels do not change (as its
  // BrickRenderer's macrocells assume): built again for the ends of the
  // last build, it keeps its bits and returns false. So a transfer-function
  // change that moves no transparent end (a colour, an opacity within the
  // visible values) costs no bitmap.
  bool build(const ClearEnds& ends, const KernelParams& p, const Brick& brick, const MacrocellBounds* bounds,
             ThreadPool* pool);

  // The bits for KernelParams::clearCells; null when there are none.
  const std::uint8_t* bits() const {
    return bits_.empty() ? nullptr : reinterpret_cast<const std::uint8_t*>(bits_.data());
  }

 private:
  std::vector<std::uint64_t> bits_;  // little-endian: bit n of the bytes is bit n % 64 of word n / 64
  std::optional<ClearEnds> builtFor_;  // the ends bits_ were built for
};

}  // namespace pvr::core
