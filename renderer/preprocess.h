// Preprocessing a brick's voxels: its value range and macrocell bounds in
// one pass, slab by slab.
//
// The pass walks node slabs (one z each). Within a slab, the rows of each
// macrocell row's node range (kSize + 1 rows) are reduced element by
// element in one pass, which the compiler vectorises, and the reduced row
// then along x by sliding windows of kSize + 1 picked on the macrocell
// lattice (vectorised too): the separable min/max. The value range is the
// macrocells' bounds plus the ghost nodes outside every macrocell. The slab's
// 2-D bounds then widen the (at most two) macrocell layers whose node range
// holds the slab. A slab's few rows stay in cache while all of this
// happens, so a reader can hand each slab over right after it lands and
// the data is touched once (raw_reader.cpp). Float data skips NaN and Inf
// in both range and bounds, and counts them. The same pass counts the
// histogram's fine keys of the voxels a brick owns (value_histogram.h,
// fine_counts.h):
// one table increment per owned voxel, one per 64 bytes of one value,
// nothing per ghost.
#pragma once

#include <cstdint>
#include <memory>

#include "brick.h"
#include "macrocell_bounds.h"
#include "value_histogram.h"

namespace pvr::core {

class ThreadPool;

struct Preprocessed {
  ValueRange range;
  std::shared_ptr<MacrocellBounds> bounds;
  // Fine counts of the voxels in the box the caller named (value_histogram.h);
  // null when it named none.
  std::shared_ptr<FineHistogram> histogram;
};

// Takes a brick's node slabs one or a few at a time, in any order, each
// once; single-threaded. For readers that fill a brick slab by slab.
class SlabPreprocessor {
 public:
  // `counted`, when given, is the box whose voxels the histogram counts
  // (countedBox of the owned box); it must lie inside `stored`.
  SlabPreprocessor(ScalarType type, const NodeBox& owned, const NodeBox& stored,
                   const NodeBox* counted = nullptr);
  ~SlabPreprocessor();
  SlabPreprocessor(const SlabPreprocessor&) = delete;
  SlabPreprocessor& operator=(const SlabPreprocessor&) = delete;

  // Folds in slabs z0..z1 (inclusive, inside the stored box) whose voxels,
  // in host byte order, start at `voxels`: stored.extent(0) per row,
  // stored.extent(1) rows per slab.
  void add(const std::byte* voxels, std::int64_t z0, std::int64_t z1);
  // The result, once every stored slab has been added.
  Preprocessed finish();

  struct Impl;  // one per scalar type, in preprocess.cpp

 private:
  std::unique_ptr<Impl> impl_;
};

// The whole stored box at once, over the pool's threads when one is given
// (chunks of macrocell layers); the result does not depend on the threads.
// With `counted`, also the fine histogram of that box, as SlabPreprocessor.
Preprocessed preprocessVoxels(ScalarType type, const NodeBox& owned, const NodeBox& stored,
                              const std::byte* voxels, ThreadPool* pool = nullptr,
                              const NodeBox* counted = nullptr);

// Only the fine histogram of the `counted` box (inside `stored`), for a
// brick that has its range and bounds: the same counts as preprocessVoxels,
// without its min/max work (a quarter of that pass for 8- and 16-bit data).
// Over the pool's threads when one is given (chunks of slabs).
std::shared_ptr<FineHistogram> countFineKeys(ScalarType type, const NodeBox& stored, const std::byte* voxels,
                                             const NodeBox& counted, ThreadPool* pool = nullptr);

}  // namespace pvr::core
