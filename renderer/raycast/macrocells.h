// Min-max macrocells for empty-space skipping.
//
// The bounds (macrocell_bounds.h) come with the brick when its reader or
// updateValueRange() computed them, and are shared, not copied; otherwise
// the grid computes them itself. A sample that rounding places in a
// neighbouring macrocell lies within ~1e-5 voxel of the shared face, where
// the reconstruction is the face nodes' values that both macrocells hold.
// Small macrocells (4^3 cells) keep thin visible structures from dragging
// whole blocks of empty space into the sample loop. Classification against
// a transfer function is one O(1) query per macrocell and a separable
// distance field (leap_distance.h), cheap enough to redo on every transfer-function
// change.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "../brick.h"
#include "../macrocell_bounds.h"
#include "../thread_pool.h"
#include "../transfer.h"

namespace pvr::core {

class MacrocellGrid {
 public:
  static constexpr int kShift = MacrocellLayout::kShift;
  static constexpr int kSize = MacrocellLayout::kSize;

  // Takes the brick's bounds, or computes them (over the pool's threads
  // when one is given) if the brick carries none.
  explicit MacrocellGrid(const Brick& brick, ThreadPool* pool = nullptr);

  // Marks each macrocell visible if the transfer function gives some value
  // in its range a non-zero opacity (all visible when skipping is off), then
  // updates the distance field. Threaded over the pool when one is given;
  // the result does not depend on it.
  void classify(const TransferTable& table, bool skipEmpty, ThreadPool* pool = nullptr);

  IVec3 first() const { return bounds_->layout().first; }  // global index of the brick's first macrocell
  IVec3 count() const { return bounds_->layout().count; }  // macrocells per axis
  const MacrocellBounds& bounds() const { return *bounds_; }
  // Chessboard distance, in macrocells, from each macrocell to the nearest
  // visible one: 0 for a visible macrocell, exact below kLeapNear, beyond
  // it a lower bound (leap_distance.h), at most 255. A ray in a macrocell at
  // distance d may leap d - 1 macrocells along its major axis without
  // meeting anything visible (space leaping with a distance field).
  const std::uint8_t* distance() const { return distance_.data(); }
  // The least box of macrocells holding every visible one, as global
  // macrocell indices [visibleFirst(), visibleLast()] per axis; empty
  // (first > last on every axis) when none is visible. Rays never walk the
  // empty shell around it (kernel::clipToVisible).
  IVec3 visibleFirst() const { return visibleFirst_; }
  IVec3 visibleLast() const { return visibleLast_; }
  // Seconds the constructor spent computing bounds (0 when the brick had them).
  double buildSeconds() const { return buildSeconds_; }

  // The fields rays leap by, one per direction octant (bit a set: the ray
  // goes down axis a; octantOf in kernel.h): for the first
  // forwardFieldsKept() octants of `wanted` (most rays first,
  // frameOctants), forwardLeapDistance's field (leap_distance.h), built
  // over the pool on first use after classify() and kept while frames want
  // it; for every other octant distance(), which is as safe and leaps less
  // far. Holds what it hands out alive until the result goes.
  struct LeapFields {
    const std::uint8_t* byOctant[8];
    std::shared_ptr<const std::vector<std::uint8_t>> held[8];
  };
  LeapFields leapFields(const std::vector<int>& wanted, ThreadPool* pool = nullptr) const;
  // How many forward fields are kept at most: a byte per macrocell each,
  // together at most 1/64 of the brick's voxel bytes (issue 11 allows a
  // rank 1.1x its share of the volume; with the field a 2048^3 rank peaks
  // at 1.09-1.10x, bench/results/scale): one for 8-bit data (a macrocell
  // holds 64 voxels), two for 16-bit, four beyond.
  int forwardFieldsKept() const;

 private:
  void findVisibleBox();  // visibleFirst_ and visibleLast_ from distance_

  std::shared_ptr<const MacrocellBounds> bounds_;
  std::vector<std::uint8_t> distance_;
  IVec3 visibleFirst_, visibleLast_;
  double buildSeconds_ = 0;
  bool skipEmpty_ = false;  // as last classified: when off, distance() is all 0 and serves every octant
  // The forward fields built since classify(), by octant (leapFields).
  struct ForwardCache {
    std::mutex mutex;
    std::shared_ptr<const std::vector<std::uint8_t>> byOctant[8];
  };
  std::unique_ptr<ForwardCache> forward_ = std::make_unique<ForwardCache>();
};

// The exact chessboard distance transform of `distance` (count.x fastest),
// in place: on entry 0 marks a visible macrocell and 255 an invisible one;
// on return each holds min(255, distance to the nearest 0). Three separable
// passes, one per axis (see macrocells.cpp). Exposed for tests.
void chessboardDistance(std::uint8_t* distance, IVec3 count, ThreadPool* pool = nullptr);

}  // namespace pvr::core
