#include "macrocells.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pvr::core {

MacrocellGrid::MacrocellGrid(const Brick& brick) {
  const NodeBox& own = brick.owned();
  const NodeBox& st = brick.stored();
  for (int a = 0; a < 3; ++a) {
    // Cells owned run from own.lo to own.hi - 1 (at least one cell unless the
    // grid is one node thick on this axis).
    const std::int64_t lastCell = std::max(own.lo[a], own.hi[a] - 1);
    first_[a] = own.lo[a] >> kShift;
    count_[a] = (lastCell >> kShift) - first_[a] + 1;
  }
  const std::size_t n = std::size_t(count_.product());
  min_.assign(n, std::numeric_limits<float>::infinity());
  max_.assign(n, -std::numeric_limits<float>::infinity());
  visible_.assign(n, 1);

  dispatchScalar(brick.type(), [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    const T* v = brick.as<T>();
    // Each stored node widens every macrocell whose node range
    // [kSize*m, kSize*m + kSize] holds it: at most two per axis.
    auto cellsOf = [&](int a, std::int64_t node, std::int64_t& m0, std::int64_t& m1) {
      // m0 = ceil((node - kSize) / kSize), m1 = floor(node / kSize);
      // >> floors negative numbers too.
      m0 = std::max<std::int64_t>(first_[a], (node - 1) >> kShift);
      m1 = std::min<std::int64_t>(first_[a] + count_[a] - 1, node >> kShift);
    };
    for (std::int64_t z = st.lo.z; z <= st.hi.z; ++z) {
      std::int64_t mz0, mz1;
      cellsOf(2, z, mz0, mz1);
      for (std::int64_t y = st.lo.y; y <= st.hi.y; ++y) {
        std::int64_t my0, my1;
        cellsOf(1, y, my0, my1);
        const T* rowp = v + brick.linearIndex({st.lo.x, y, z});
        for (std::int64_t x = st.lo.x; x <= st.hi.x; ++x) {
          const float val = float(rowp[x - st.lo.x]);
          if (!std::isfinite(val)) continue;
          std::int64_t mx0, mx1;
          cellsOf(0, x, mx0, mx1);
          for (std::int64_t mz = mz0; mz <= mz1; ++mz)
            for (std::int64_t my = my0; my <= my1; ++my)
              for (std::int64_t mx = mx0; mx <= mx1; ++mx) {
                const std::size_t i = std::size_t(((mz - first_.z) * count_.y + (my - first_.y)) *
                                                      count_.x + (mx - first_.x));
                min_[i] = std::min(min_[i], val);
                max_[i] = std::max(max_[i], val);
              }
        }
      }
    }
    return 0;
  });
}

void MacrocellGrid::classify(const TransferTable& table, bool skipEmpty) {
  for (std::size_t i = 0; i < visible_.size(); ++i)
    visible_[i] = !skipEmpty || (min_[i] <= max_[i] && table.anyVisible(min_[i], max_[i]));
  updateDistances();
}

void MacrocellGrid::updateDistances() {
  // Two raster passes of a chamfer transform with the 26-neighbourhood give
  // the exact chessboard distance: forward with the neighbours already
  // visited, backward with the others.
  const int nx = int(count_.x), ny = int(count_.y), nz = int(count_.z);
  distance_.assign(visible_.size(), 255);
  auto at = [&](int x, int y, int z) -> std::uint8_t& {
    return distance_[(std::size_t(z) * ny + y) * nx + x];
  };
  for (std::size_t i = 0; i < visible_.size(); ++i)
    if (visible_[i]) distance_[i] = 0;
  auto relax = [&](int x, int y, int z, int dirSign) {
    std::uint8_t& d = at(x, y, z);
    for (int dz = -1; dz <= 0; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          // Neighbours earlier in this pass's raster order.
          if (dz == 0 && (dy > 0 || (dy == 0 && dx >= 0))) continue;
          const int qx = x + dirSign * dx, qy = y + dirSign * dy, qz = z + dirSign * dz;
          if (qx < 0 || qy < 0 || qz < 0 || qx >= nx || qy >= ny || qz >= nz) continue;
          d = std::uint8_t(std::min<int>(d, at(qx, qy, qz) + 1));
        }
  };
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) relax(x, y, z, 1);
  for (int z = nz - 1; z >= 0; --z)
    for (int y = ny - 1; y >= 0; --y)
      for (int x = nx - 1; x >= 0; --x) relax(x, y, z, -1);
}

}  // namespace pvr::core
