#include "kernel_setup.h"

#include <algorithm>
#include <bit>
#include <cfloat>
#include <cmath>

namespace pvr::core {

void setBrick(KernelParams& p, const Brick& brick, const MacrocellGrid& macrocells) {
  const GridGeometry& grid = brick.grid();
  const NodeBox& own = brick.owned();
  const NodeBox& st = brick.stored();
  p.voxels = brick.bytes();
  const IVec3 ext = st.extents();
  p.strideY = ext.x;
  p.strideZ = ext.x * ext.y;
  p.base = -(st.lo.x + st.lo.y * p.strideY + st.lo.z * p.strideZ);
  const auto log2Exact = [](std::int64_t n) {
    return n > 0 && std::has_single_bit(std::uint64_t(n)) ? std::countr_zero(std::uint64_t(n)) : -1;
  };
  const int shiftY = log2Exact(p.strideY), shiftZ = log2Exact(p.strideZ);
  p.strideShift[0] = shiftY >= 0 && shiftZ >= 0 ? shiftY : -1;
  p.strideShift[1] = shiftY >= 0 && shiftZ >= 0 ? shiftZ : -1;
  p.indices32 = st.nodeCount() < (std::int64_t(1) << 31) - 1;
  for (int a = 0; a < 3; ++a) {
    p.ownLo[a] = double(own.lo[a]);
    p.ownHi[a] = double(own.hi[a]);
    p.hiClosed[a] = own.hi[a] == grid.dims[a] - 1;
    p.ownCellLo[a] = int(own.lo[a]);
    p.ownCellHi[a] = int(std::max(own.lo[a], own.hi[a] - 1));
    p.storedCellLo[a] = int(st.lo[a]);
    p.storedCellHi[a] = int(std::max(st.lo[a], st.hi[a] - 1));
    p.domainMax[a] = float(grid.dims[a] - 1);
    p.invSpacing[a] = float(1.0 / grid.spacing[a]);
    p.mcFirst[a] = int(macrocells.first()[a]);
    p.mcCount[a] = int(macrocells.count()[a]);
    // A float position's rounding error stays far below the voxel the box
    // is widened by for any position within 2^20 voxels of the grid.
    const std::int64_t lo = macrocells.visibleFirst()[a], hi = macrocells.visibleLast()[a];
    const std::int64_t edgeLo = macrocells.first()[a], edgeHi = edgeLo + macrocells.count()[a] - 1;
    constexpr int kShift = MacrocellGrid::kShift;
    if (lo > hi) {
      p.visibleLo[a] = 1;
      p.visibleHi[a] = 0;
    } else {
      p.visibleLo[a] = lo == edgeLo ? -1e30 : double(lo << kShift) - 1.0;
      p.visibleHi[a] = hi == edgeHi ? 1e30 : double((hi + 1) << kShift) + 1.0;
    }
  }
  p.distance = macrocells.distance();
  for (auto& field : p.leapField) field = p.distance;
}

std::vector<int> frameOctants(const Camera& camera, const PixelRect& rect) {
  if (rect.empty()) return {};
  // A camera ray's direction is a linear function of the pixel's
  // position, normalised: over a rectangle of pixels each component takes
  // its extremes, and so both of its signs if it has them, at the corners.
  // An 8 x 8 grid of rays through the rectangle, corners included, finds
  // every octant and roughly each one's share of the rays.
  constexpr int kAcross = 8;
  int rays[8] = {};
  for (int j = 0; j < kAcross; ++j)
    for (int i = 0; i < kAcross; ++i) {
      const int x = rect.x0 + int(std::int64_t(rect.width() - 1) * i / (kAcross - 1));
      const int y = rect.y0 + int(std::int64_t(rect.height() - 1) * j / (kAcross - 1));
      ++rays[kernel::directionOctant(camera.ray(x, y).direction)];
    }
  std::vector<int> octants;
  for (int o = 0; o < 8; ++o)
    if (rays[o] > 0) octants.push_back(o);
  std::stable_sort(octants.begin(), octants.end(), [&](int a, int b) { return rays[a] > rays[b]; });
  return octants;
}

void setLeapFields(KernelParams& p, const MacrocellGrid::LeapFields& fields) {
  for (int o = 0; o < 8; ++o) p.leapField[o] = fields.byOctant[o];
}

void ownRegion(KernelParams& p, const GridGeometry& grid, const WorldRegion& region) {
  for (int a = 0; a < 3; ++a) {
    const double lo = (region.lo[a] - grid.origin[a]) / grid.spacing[a];
    const double hi = (region.hi[a] - grid.origin[a]) / grid.spacing[a];
    const double last = double(grid.dims[a] - 1);
    p.ownLo[a] = std::max(0.0, lo);
    p.ownHi[a] = std::min(last, hi);
    p.hiClosed[a] = hi > last;
  }
}

void setTables(KernelParams& p, const TransferTable& table, const PreintegratedTable* preintegrated,
               double step) {
  p.table = table.entries();
  p.tableEntries = TransferTable::kEntries;
  p.tableScale = table.scale();
  p.tableOffset = table.offset();
  // The transparent ends of the table: entries before the first and after
  // the last that has any non-zero channel.
  const Rgba* e = table.entries();
  const int n = TransferTable::kEntries;
  auto zero = [](const Rgba& c) { return c.r == 0 && c.g == 0 && c.b == 0 && c.a == 0; };
  int first = 0, last = n - 1;
  while (first < n && zero(e[first])) ++first;
  while (last >= 0 && zero(e[last])) --last;
  // classify1D reads entries i and i + 1, i = min(int(x), n - 2): both are
  // zero when i + 1 < first, i.e. x < first - 1, or when i > last, i.e.
  // x >= last + 1 with last + 1 <= n - 2.
  p.clearBelow = first == n ? FLT_MAX : float(first - 1);
  p.clearAbove = first == n || last + 1 > n - 2 ? FLT_MAX : float(last + 1);
  p.preint = preintegrated ? preintegrated->tables() : PreintegralTables{};
  p.stepLength = step;
}

void setLevels(KernelParams& p, const StepLevels& levels, const std::vector<TransferTable>& tables,
               double fineStep, std::vector<KernelParams>& atLevel) {
  p.levels = levels.levels();
  for (int a = 0; a < 3; ++a) {
    p.lvFirst[a] = int(levels.first()[a]);
    p.lvCount[a] = int(levels.count()[a]);
    p.lvDomainLast[a] = int(levels.domainCount()[a] - 1);
  }
  atLevel.assign(tables.size(), p);
  for (std::size_t l = 0; l < tables.size(); ++l) {
    KernelParams& level = atLevel[l];
    setTables(level, tables[l], nullptr, fineStep * double(std::int64_t(1) << l));
    // The clear cells are p's table's: a level's table with other
    // transparent ends does not read them.
    if (level.clearBelow != p.clearBelow || level.clearAbove != p.clearAbove) level.clearCells = nullptr;
  }
  p.atLevel = atLevel.data();
}

void setOptions(KernelParams& p, const RenderOptions& options, const float* specularTable) {
  p.earlyTermination = float(std::clamp(options.earlyTermination, 0.0, 1.0));
  p.ambient = float(options.shading.ambient);
  p.diffuse = float(options.shading.diffuse);
  p.specular = float(options.shading.specular);
  p.shininess = float(options.shading.shininess);
  p.specularTable = specularTable;
  if (kernel::powerBits(options.shading.shininess) != kernel::kTablePower)
    kernel::setPowerFloor(int(options.shading.shininess), p.powerFloor);
}

std::vector<float> specularTable(double shininess) {
  std::vector<float> table(kSpecularTableSize);
  for (int i = 0; i < kSpecularTableSize; ++i)
    table[i] = float(std::pow(double(i) / (kSpecularTableSize - 1), shininess));
  return table;
}

namespace {

// Three coordinates and a spare lane, for a ray's set-up: its divisions
// (by the spacing, the reciprocals, the half vector's normalisation) as
// vector divisions. Each lane is the same IEEE operation as the scalar
// one, so the bits are those of the per-axis code this replaced (images
// identical), in less time: 19 -> 14 ns a ray unshaded, 29 -> 21 ns
// shaded, where set-up had been 5 % of a shaded CT head frame. A lane
// whose step is 0 divides by 0 too, and the select drops its infinity
// (nothing here traps floating-point exceptions).
using Lanes = double __attribute__((vector_size(32)));

Lanes lanes(const Vec3& v, double spare) { return Lanes{v.x, v.y, v.z, spare}; }

}  // namespace

RaySetup raySetup(const Ray& ray, const GridGeometry& grid, double step) {
  RaySetup s{};  // the lighting vectors zero
  const Lanes spacing = lanes(grid.spacing, 1.0);
  const Lanes origin = (lanes(ray.origin, 0.0) - lanes(grid.origin, 0.0)) / spacing;
  const Lanes stride = lanes(ray.direction, 0.0) * step / spacing;
  const Lanes inverse = stride != 0 ? 1.0 / stride : Lanes{};
  for (int a = 0; a < 3; ++a) {
    s.origin[a] = origin[a];
    s.step[a] = stride[a];
    s.invStep[a] = inverse[a];
  }
  const double major = std::max({std::abs(s.step[0]), std::abs(s.step[1]), std::abs(s.step[2])});
  s.leapPerMacrocell = double(MacrocellGrid::kSize) / major;
  return s;
}

RaySetup raySetup(const Ray& ray, const GridGeometry& grid, double step, const Vec3& lightWorld) {
  RaySetup s = raySetup(ray, grid, step);
  // Headlight by default: the light direction is fixed in camera space.
  // The viewer looks back along the ray.
  const Vec3 sum = lightWorld - ray.direction;
  const double norm = length(sum);
  const Lanes halfway = norm > 1e-9 ? lanes(sum, 0.0) / norm : lanes(lightWorld, 0.0);
  for (int a = 0; a < 3; ++a) {
    s.light[a] = float(lightWorld[a]);
    s.halfway[a] = float(halfway[a]);
  }
  return s;
}

}  // namespace pvr::core
