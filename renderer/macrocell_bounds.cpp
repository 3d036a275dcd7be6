#include "macrocell_bounds.h"

#include <algorithm>

#include "brick.h"

namespace pvr::core {

MacrocellLayout MacrocellLayout::forOwned(const NodeBox& owned) {
  MacrocellLayout l;
  for (int a = 0; a < 3; ++a) {
    // Cells owned run from owned.lo to owned.hi - 1 (at least one cell
    // unless the grid is one node thick on this axis).
    const std::int64_t lastCell = std::max(owned.lo[a], owned.hi[a] - 1);
    l.first[a] = owned.lo[a] >> kShift;
    l.count[a] = (lastCell >> kShift) - l.first[a] + 1;
  }
  return l;
}

MacrocellBounds::MacrocellBounds(ScalarType type, const MacrocellLayout& layout)
    : type_(type), layout_(layout) {
  const std::size_t n = layout.size();
  min_.resize(n * scalarSize(type));
  max_.resize(n * scalarSize(type));
  dispatchScalar(type, [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    std::fill_n(min<T>(), n, emptyMin<T>());
    std::fill_n(max<T>(), n, emptyMax<T>());
  });
}

double MacrocellBounds::minAt(std::size_t i) const {
  return dispatchScalar(type_, [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    return double(min<T>()[i]);
  });
}

double MacrocellBounds::maxAt(std::size_t i) const {
  return dispatchScalar(type_, [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    return double(max<T>()[i]);
  });
}

}  // namespace pvr::core
