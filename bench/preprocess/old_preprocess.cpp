#include "old_preprocess.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pvr::bench {

using namespace core;

ValueRange oldValueRange(const Brick& brick) {
  return dispatchScalar(brick.type(), [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    const T* v = brick.as<T>();
    const std::size_t n = std::size_t(brick.stored().nodeCount());
    double lo = std::numeric_limits<double>::infinity();
    double hi = -lo;
    std::uint64_t bad = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double x = double(v[i]);
      if (!std::isfinite(x)) {
        ++bad;
        continue;
      }
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
    if (lo > hi) lo = hi = 0;
    return ValueRange{lo, hi, bad};
  });
}

OldMacrocells oldMacrocellBounds(const Brick& brick) {
  constexpr int kShift = MacrocellLayout::kShift;
  OldMacrocells m;
  m.layout = MacrocellLayout::forOwned(brick.owned());
  const IVec3 first = m.layout.first, count = m.layout.count;
  const NodeBox& st = brick.stored();
  const std::size_t n = m.layout.size();
  m.min.assign(n, std::numeric_limits<float>::infinity());
  m.max.assign(n, -std::numeric_limits<float>::infinity());
  m.visible.assign(n, 1);
  dispatchScalar(brick.type(), [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    const T* v = brick.as<T>();
    auto cellsOf = [&](int a, std::int64_t node, std::int64_t& m0, std::int64_t& m1) {
      m0 = std::max<std::int64_t>(first[a], (node - 1) >> kShift);
      m1 = std::min<std::int64_t>(first[a] + count[a] - 1, node >> kShift);
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
                const std::size_t i = std::size_t(((mz - first.z) * count.y + (my - first.y)) * count.x + (mx - first.x));
                m.min[i] = std::min(m.min[i], val);
                m.max[i] = std::max(m.max[i], val);
              }
        }
      }
    }
    return 0;
  });
  return m;
}

void oldClassify(OldMacrocells& m, const TransferTable& table) {
  for (std::size_t i = 0; i < m.visible.size(); ++i)
    m.visible[i] = m.min[i] <= m.max[i] && table.anyVisible(m.min[i], m.max[i]);
  const int nx = int(m.layout.count.x), ny = int(m.layout.count.y), nz = int(m.layout.count.z);
  m.distance.assign(m.visible.size(), 255);
  auto at = [&](int x, int y, int z) -> std::uint8_t& { return m.distance[(std::size_t(z) * ny + y) * nx + x]; };
  for (std::size_t i = 0; i < m.visible.size(); ++i)
    if (m.visible[i]) m.distance[i] = 0;
  auto relax = [&](int x, int y, int z, int dirSign) {
    std::uint8_t& d = at(x, y, z);
    for (int dz = -1; dz <= 0; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
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

ContentGrid oldCountContent(const Brick& brick, const TransferTable& table) {
  const GridGeometry& grid = brick.grid();
  ContentGrid c = makeContentGrid(grid);
  const NodeBox& own = brick.owned();
  IVec3 end;
  for (int a = 0; a < 3; ++a) end[a] = own.hi[a] == grid.dims[a] - 1 ? own.hi[a] + 1 : own.hi[a];
  auto blockOf = [&](int a, std::int64_t n) { return std::min(n / c.blockCells[a], c.blocks[a] - 1); };
  dispatchScalar(brick.type(), [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    const T* v = brick.as<T>();
    for (std::int64_t z = own.lo.z; z < end.z; ++z)
      for (std::int64_t y = own.lo.y; y < end.y; ++y) {
        const std::size_t rowBlocks = std::size_t((blockOf(2, z) * c.blocks.y + blockOf(1, y)) * c.blocks.x);
        const T* row = v + brick.linearIndex({own.lo.x, y, z});
        for (std::int64_t x = own.lo.x; x < end.x; ++x) {
          const double s = double(row[x - own.lo.x]);
          if (std::isfinite(s) && table.anyVisible(s, s)) ++c.counts[rowBlocks + std::size_t(blockOf(0, x))];
        }
      }
  });
  return c;
}

}  // namespace pvr::bench
