#include "raycaster.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <vector>

#include "../error.h"
#include "cast_ray.h"

namespace pvr::core {

namespace {

constexpr int kTileSize = 16;

using RayFunction = RayResult (*)(const KernelParams&, const RaySetup&, int);

// The one place configuration picks a kernel instantiation.
template <typename T>
RayFunction pickKernel(bool shaded, bool preintegrated) {
  if (shaded) return preintegrated ? &castRay<T, true, true> : &castRay<T, true, false>;
  return preintegrated ? &castRay<T, false, true> : &castRay<T, false, false>;
}

RayFunction pickKernel(ScalarType type, bool shaded, bool preintegrated) {
  return dispatchScalar(type, [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    return pickKernel<T>(shaded, preintegrated);
  });
}

}  // namespace

RenderOptions renderOptionsFor(const Scene& scene) {
  RenderOptions o;
  o.step = scene.sampling.step;
  o.earlyTermination = scene.sampling.earlyTermination;
  o.preintegrated = scene.sampling.preintegrated;
  o.shading = scene.shading;
  return o;
}

int ghostLayers(const GridGeometry& grid, const RenderOptions& options) {
  int layers = options.shading.enabled ? 1 : 0;
  if (options.preintegrated)
    layers = std::max(layers, int(std::ceil(options.step / grid.minSpacing() - 1e-9)));
  return layers;
}

BrickRenderer::BrickRenderer(const Brick& brick, ThreadPool* pool) : brick_(brick), macrocells_(brick, pool) {}

void BrickRenderer::classify(const TransferFunctionSpec& tf, const RenderOptions& options, ThreadPool* pool) {
  table_ = TransferTable(tf, options.step);
  preintegrated_.reset();
  if (options.preintegrated) preintegrated_ = std::make_unique<PreintegratedTable>(tf, options.step);
  macrocells_.classify(table_, options.skipEmpty, pool);
  classifiedStep_ = options.step;
}

Image BrickRenderer::render(const Camera& camera, const RenderOptions& options, ThreadPool& pool,
                            RenderStats* stats, const PixelRect* region) const {
  const auto started = std::chrono::steady_clock::now();
  if (options.step != classifiedStep_ || options.preintegrated != bool(preintegrated_))
    throw Error(ErrorCode::kInternal, "BrickRenderer::render: classify() was called with other options");

  const GridGeometry& grid = brick_.grid();
  const NodeBox& own = brick_.owned();
  const NodeBox& st = brick_.stored();

  // Screen rectangle of the owned box; a grid one node thick has no cells
  // and shows nothing.
  const Vec3 lo = grid.nodePosition(own.lo), hi = grid.nodePosition(own.hi);
  bool degenerate = false;
  for (int a = 0; a < 3; ++a) degenerate |= grid.dims[a] < 2;
  PixelRect rect = degenerate ? PixelRect{} : camera.project(lo, hi);
  if (region) rect = rect.intersect(*region);
  Image image(camera.width(), camera.height(), rect);
  if (image.rect().empty()) {
    if (stats) *stats = {};
    return image;
  }

  // Set up what does not change per ray.
  KernelParams p;
  p.voxels = brick_.bytes();
  const IVec3 ext = st.extents();
  p.strideY = ext.x;
  p.strideZ = ext.x * ext.y;
  p.base = -(st.lo.x + st.lo.y * p.strideY + st.lo.z * p.strideZ);
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
    p.mcFirst[a] = int(macrocells_.first()[a]);
    p.mcCount[a] = int(macrocells_.count()[a]);
  }
  p.distance = macrocells_.distance();
  if (preintegrated_) {
    p.table = preintegrated_->entries();
    p.tableEntries = PreintegratedTable::kEntries;
    p.tableScale = preintegrated_->scale();
    p.tableOffset = preintegrated_->offset();
  } else {
    p.table = table_.entries();
    p.tableEntries = TransferTable::kEntries;
    p.tableScale = table_.scale();
    p.tableOffset = table_.offset();
  }
  p.earlyTermination = float(std::clamp(options.earlyTermination, 0.0, 1.0));
  p.ambient = float(options.shading.ambient);
  p.diffuse = float(options.shading.diffuse);
  p.specular = float(options.shading.specular);
  p.shininess = float(options.shading.shininess);
  std::vector<float> specularTable(kSpecularTableSize);
  for (int i = 0; i < kSpecularTableSize; ++i)
    specularTable[i] = float(std::pow(double(i) / (kSpecularTableSize - 1), options.shading.shininess));
  p.specularTable = specularTable.data();
  const RayFunction cast = pickKernel(brick_.type(), options.shading.enabled, bool(preintegrated_));
  const Vec3 lightWorld = normalize(camera.toWorld(options.shading.lightDirection));

  // Tiles of the rectangle over the pool; each worker counts its own work.
  const PixelRect r = image.rect();
  const int tilesX = (r.width() + kTileSize - 1) / kTileSize;
  const int tilesY = (r.height() + kTileSize - 1) / kTileSize;
  std::atomic<std::uint64_t> totalSamples{0}, totalRays{0};
  const auto stopped = [&] { return options.stop && options.stop->load(std::memory_order_relaxed); };
  pool.parallelFor(std::size_t(tilesX) * tilesY, [&](std::size_t tile, int) {
    if (stopped()) return;
    const int tx = int(tile % tilesX), ty = int(tile / tilesX);
    const int x0 = r.x0 + tx * kTileSize, y0 = r.y0 + ty * kTileSize;
    const int x1 = std::min(r.x1, x0 + kTileSize), y1 = std::min(r.y1, y0 + kTileSize);
    std::uint64_t samples = 0, rays = 0;
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; ++x) {
        const Ray ray = camera.ray(x, y);
        RaySetup s;
        for (int a = 0; a < 3; ++a) {
          s.origin[a] = (ray.origin[a] - grid.origin[a]) / grid.spacing[a];
          s.step[a] = ray.direction[a] * options.step / grid.spacing[a];
          s.invStep[a] = s.step[a] != 0 ? 1.0 / s.step[a] : 0.0;
        }
        const double major = std::max({std::abs(s.step[0]), std::abs(s.step[1]), std::abs(s.step[2])});
        s.leapPerMacrocell = double(MacrocellGrid::kSize) / major;
        // Headlight by default: the light direction is fixed in camera space.
        // The viewer looks back along the ray.
        const Vec3 view = -ray.direction;
        const Vec3 sum = lightWorld + view;
        const Vec3 halfway = length(sum) > 1e-9 ? normalize(sum) : lightWorld;
        for (int a = 0; a < 3; ++a) {
          s.light[a] = float(lightWorld[a]);
          s.halfway[a] = float(halfway[a]);
        }
        const RayResult res = cast(p, s, MacrocellGrid::kShift);
        image.at(x, y) = res.colour;
        samples += res.samples;
        rays += res.hit ? 1 : 0;
      }
    }
    totalSamples += samples;
    totalRays += rays;
    if (options.tilesDone) options.tilesDone->fetch_add(1, std::memory_order_relaxed);
  });
  if (stopped()) throw Error(ErrorCode::kCancelled, "cancelled");

  if (stats) {
    stats->samples = totalSamples;
    stats->rays = totalRays;
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  }
  return image;
}

}  // namespace pvr::core
