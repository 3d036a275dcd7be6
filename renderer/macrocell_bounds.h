// Macrocell bounds: the value bounds that empty-space skipping classifies.
//
// The grid's cells are grouped into macrocells of kSize^3 cells, aligned to
// the global grid (macrocell m covers cells [kSize*m, kSize*m + kSize)), so
// a brick and the whole volume skip the same space. A brick has the
// macrocells of the cells it owns. Each macrocell keeps the finite min and
// max of the stored nodes its cells interpolate (kSize + 1 per axis, nodes
// [kSize*m, kSize*m + kSize]), in the data's own scalar type: a uint8 brick
// spends two bytes per 64 cells on them. A macrocell with no finite node
// (float data only) keeps min > max.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "grid.h"

namespace pvr::core {

struct MacrocellLayout {
  static constexpr int kShift = 2;
  static constexpr int kSize = 1 << kShift;  // cells per macrocell edge

  IVec3 first;  // global index of the first macrocell
  IVec3 count;  // macrocells per axis

  // The macrocells of the cells `owned` holds (at least one per axis, even
  // where the grid is one node thick).
  static MacrocellLayout forOwned(const NodeBox& owned);
  std::size_t size() const { return std::size_t(count.product()); }
  bool operator==(const MacrocellLayout&) const = default;
};

// The value a min accumulator starts from (nothing seen yet), and the max's.
template <typename T> constexpr T emptyMin() {
  if constexpr (std::numeric_limits<T>::has_infinity) return std::numeric_limits<T>::infinity();
  else return std::numeric_limits<T>::max();
}
template <typename T> constexpr T emptyMax() {
  if constexpr (std::numeric_limits<T>::has_infinity) return -std::numeric_limits<T>::infinity();
  else return std::numeric_limits<T>::lowest();
}

class MacrocellBounds {
 public:
  // Every macrocell starts empty (min = emptyMin, max = emptyMax).
  MacrocellBounds(ScalarType type, const MacrocellLayout& layout);

  ScalarType type() const { return type_; }
  const MacrocellLayout& layout() const { return layout_; }
  std::size_t byteSize() const { return min_.size() + max_.size(); }

  // Macrocell (x, y, z) relative to layout().first is at (z*count.y + y)*count.x + x.
  template <typename T> T* min() { return reinterpret_cast<T*>(min_.data()); }
  template <typename T> T* max() { return reinterpret_cast<T*>(max_.data()); }
  template <typename T> const T* min() const { return reinterpret_cast<const T*>(min_.data()); }
  template <typename T> const T* max() const { return reinterpret_cast<const T*>(max_.data()); }
  // One macrocell's bounds as double; for tests and set-up, not hot loops.
  double minAt(std::size_t i) const;
  double maxAt(std::size_t i) const;

 private:
  ScalarType type_;
  MacrocellLayout layout_;
  std::vector<std::byte> min_, max_;
};

}  // namespace pvr::core
