// Min-max macrocells for empty-space skipping.
//
// The grid's cells are grouped into macrocells of kSize^3 cells, aligned to
// the global grid (macrocell m covers cells [kSize*m, kSize*m + kSize)), so
// a brick and the whole volume skip the same space. Each macrocell keeps the
// finite min and max of the nodes its cells interpolate (kSize + 1 per
// axis). A sample that rounding places in a neighbouring macrocell lies
// within ~1e-5 voxel of the shared face, where the reconstruction is the
// face nodes' values that both macrocells hold. Small macrocells (4^3
// cells) keep thin visible structures from dragging whole blocks of empty
// space into the sample loop. Classification against a
// transfer function is one O(1) query per macrocell, cheap enough to redo on
// every transfer-function change.
#pragma once

#include <cstdint>
#include <vector>

#include "../brick.h"
#include "../transfer.h"

namespace pvr::core {

class MacrocellGrid {
 public:
  static constexpr int kShift = 2;
  static constexpr int kSize = 1 << kShift;  // cells per macrocell edge

  MacrocellGrid() = default;
  explicit MacrocellGrid(const Brick& brick);

  // Marks each macrocell visible if the transfer function gives some value
  // in its range a non-zero opacity; all visible when skipping is off.
  void classify(const TransferTable& table, bool skipEmpty);

  IVec3 first() const { return first_; }    // global index of the brick's first macrocell
  IVec3 count() const { return count_; }    // macrocells per axis
  const std::uint8_t* visible() const { return visible_.data(); }
  // Chessboard distance, in macrocells, from each macrocell to the nearest
  // visible one (0 for visible macrocells, capped at 255). A ray in a
  // macrocell at distance d may leap d - 1 macrocells along its major axis
  // without meeting anything visible (space leaping with a distance field).
  const std::uint8_t* distance() const { return distance_.data(); }

 private:
  IVec3 first_, count_;
  std::vector<float> min_, max_;
  std::vector<std::uint8_t> visible_;
  std::vector<std::uint8_t> distance_;

  void updateDistances();
};

}  // namespace pvr::core
