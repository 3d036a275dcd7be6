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
// Integer voxels only (8 and 16 bits): their differences are exact in
// float, and they have no NaN. The bit of a cell is that of the voxel index
// (KernelParams) of its lowest node: 1/8 byte per stored voxel.
#pragma once

#include <cstdint>
#include <vector>

#include "../brick.h"
#include "../thread_pool.h"

namespace pvr::core {

struct KernelParams;

class ClearCells {
 public:
  // The clear cells of `brick`'s stored box, classified by p's table
  // (setBrick and setTables of this brick); none for a float brick, a box
  // without cells or a table with no transparent end.
  void build(const KernelParams& p, const Brick& brick, ThreadPool* pool);

  // The bits for KernelParams::clearCells; null when there are none.
  const std::uint8_t* bits() const {
    return bits_.empty() ? nullptr : reinterpret_cast<const std::uint8_t*>(bits_.data());
  }

 private:
  std::vector<std::uint64_t> bits_;  // little-endian: bit n of the bytes is bit n % 64 of word n / 64
};

}  // namespace pvr::core
