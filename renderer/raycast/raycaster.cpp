#include "raycaster.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <vector>

#include "../error.h"
#include "cast_ray.h"
#include "cast_ray_levels.h"
#include "kernel_setup.h"
#include "tile_start.h"
#include "tiles.h"

namespace pvr::core {

namespace {

// Casts rays[0, n) into out[0, n), n <= kRaysAtOnce, whose samples outside
// the span lie in invisible macrocells (tileSpan()).
using RayFunction = void (*)(const KernelParams&, const RaySetup*, int, int, const kernel::TileSpan&, RayResult*);

// The one place configuration picks a kernel instantiation. Plain shaded
// kernels raise a whole shininess's power (of `powerBits` bits; 0 for any
// other shininess) by steps (specular_power.h), as many as its bits rounded
// up to 5 (shininess up to 31), 6 (up to 63) or 8: each step is two
// dependent multiplies in the lit batch's chain, and 8 steps for shininess
// 24 measured 2 % slower than 5. Other shininesses and pre-integrated
// kernels read the table.
template <typename T>
RayFunction pickKernel(bool shaded, bool preintegrated, int powerBits) {
  if (!shaded) return preintegrated ? &castRays<T, false, true> : &castRays<T, false, false>;
  if (preintegrated) return &castRays<T, true, true>;
  if (powerBits == kernel::kTablePower) return &castRays<T, true, false>;
  if (powerBits <= 5) return &castRays<T, true, false, 5>;
  return powerBits <= 6 ? &castRays<T, true, false, 6> : &castRays<T, true, false, kernel::kPowerBits>;
}

RayFunction pickKernel(ScalarType type, bool shaded, bool preintegrated, int powerBits) {
  return dispatchScalar(type, [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    return pickKernel<T>(shaded, preintegrated, powerBits);
  });
}

// The kernel that picks the step per region (plain sampling only).
RayFunction pickLevelKernel(ScalarType type, bool shaded) {
  return dispatchScalar(type, [&](auto tag) -> RayFunction {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    return shaded ? &castRaysByLevels<T, true> : &castRaysByLevels<T, false>;
  });
}

// Quality chosen by error applies to these options (RenderOptions::targetPsnr).
bool byLevels(const RenderOptions& options) { return options.targetPsnr > 0 && !options.preintegrated; }

}  // namespace

RenderOptions renderOptionsFor(const Scene& scene) {
  RenderOptions o;
  o.step = scene.sampling.step;
  o.earlyTermination = scene.sampling.earlyTermination;
  o.preintegrated = scene.sampling.preintegrated;
  o.targetPsnr = scene.sampling.targetPsnr;
  o.shading = scene.shading;
  return o;
}

int ghostLayers(const GridGeometry& grid, const RenderOptions& options) {
  int layers = options.shading.enabled ? 1 : 0;
  if (options.preintegrated) {
    const double steps = options.step / grid.minSpacing();
    // A segment's back node is corrected with the sample one step further
    // on (curvedNode()): reads reach two steps beyond the owned box.
    layers = std::max(layers, int(std::ceil(2 * steps - 1e-9)));
    // Lit inside its segment, up to a step beyond the last owned sample,
    // with central differences one voxel further (within the two steps
    // above from a step of one voxel on).
    if (options.shading.enabled) layers = std::max(layers, int(std::ceil(steps - 1e-9)) + 1);
  }
  if (byLevels(options)) layers = std::max(layers, levelGhostLayers(grid, options.step));
  return layers;
}

BrickRenderer::BrickRenderer(const Brick& brick, ThreadPool* pool) : brick_(brick), macrocells_(brick, pool) {}

void BrickRenderer::classify(const TransferFunctionSpec& tf, const RenderOptions& options, ThreadPool* pool) {
  levelTables_.clear();
  // A brick of a several-volume scene keeps the scene's step (raycaster.h).
  if (byLevels(options) && !region_) {
    if (!levels_ || levels_->sceneStep() != options.step)
      levels_ = std::make_unique<StepLevels>(brick_, options.step, pool);
    levels_->choose(tf, options.targetPsnr,
                    options.shading.enabled ? options.shading.diffuse + options.shading.specular : 0.0);
    for (int l = 0; l < kStepLevels; ++l) levelTables_.emplace_back(tf, fineStep(options.step) * double(1 << l));
  }
  table_ = levelTables_.empty() ? TransferTable(tf, options.step) : levelTables_.front();
  preintegrated_.reset();
  if (options.preintegrated) preintegrated_ = std::make_unique<PreintegratedTable>(tf);
  macrocells_.classify(table_, options.skipEmpty, pool);
  // The clear cells of the table the batches read: each plain sample's,
  // or the segments' one end (clear_cells.h).
  KernelParams byTable;
  setBrick(byTable, brick_, macrocells_);
  setTables(byTable, table_, preintegrated_.get(), options.step);
  clearCells_.build(preintegrated_ ? ClearEnds::ofSegments(byTable.preint) : ClearEnds::ofSamples(byTable), byTable,
                    brick_, &macrocells_.bounds(), pool);
  classifiedStep_ = options.step;
}

Image BrickRenderer::render(const Camera& camera, const RenderOptions& options, ThreadPool& pool,
                            RenderStats* stats, const PixelRect* region) const {
  const auto started = std::chrono::steady_clock::now();
  if (options.step != classifiedStep_ || options.preintegrated != bool(preintegrated_))
    throw Error(ErrorCode::kInternal, "BrickRenderer::render: classify() was called with other options");

  const GridGeometry& grid = brick_.grid();
  const NodeBox& own = brick_.owned();

  // Screen rectangle of the owned box (or the region's part of the
  // domain); a grid one node thick has no cells and shows nothing.
  Vec3 lo = grid.nodePosition(own.lo), hi = grid.nodePosition(own.hi);
  bool degenerate = false;
  for (int a = 0; a < 3; ++a) degenerate |= grid.dims[a] < 2;
  if (region_) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(grid.domainMin()[a], region_->lo[a]);
      hi[a] = std::min(grid.domainMax()[a], region_->hi[a]);
      degenerate |= lo[a] > hi[a];
    }
  }
  PixelRect rect = degenerate ? PixelRect{} : camera.project(lo, hi);
  if (region) rect = rect.intersect(*region);
  Image image(camera.width(), camera.height(), rect);
  if (image.rect().empty()) {
    if (stats) *stats = {};
    return image;
  }

  // Set up what does not change per ray.
  KernelParams p;
  setBrick(p, brick_, macrocells_);
  // Each ray leaps by the empty box ahead of it in its direction octant.
  const MacrocellGrid::LeapFields leapFields = macrocells_.leapFields(frameOctants(camera, image.rect()), &pool);
  setLeapFields(p, leapFields);
  if (region_) ownRegion(p, grid, *region_);
  const bool levelled = !levelTables_.empty();
  // The rays' sample spacing.
  const double step = levelled          ? fineStep(options.step)
                      : preintegrated_ ? preint::sampleSpacing(options.step, grid.minSpacing())
                                       : options.step;
  setTables(p, table_, preintegrated_.get(), step);
  p.clearCells = clearCells_.bits();
  const std::vector<float> specular = specularTable(options.shading.shininess);
  setOptions(p, options, specular.data());
  std::vector<KernelParams> atLevel;
  if (levelled) setLevels(p, *levels_, levelTables_, step, atLevel);
  const RayFunction cast = levelled ? pickLevelKernel(brick_.type(), options.shading.enabled)
                                    : pickKernel(brick_.type(), options.shading.enabled, bool(preintegrated_),
                                                 kernel::powerBits(options.shading.shininess));
  const Vec3 lightWorld = normalize(camera.toWorld(options.shading.lightDirection));
  const bool shaded = options.shading.enabled;  // only shaded kernels read a ray's lighting vectors

  // Tiles of the rectangle over the pool; each worker counts its own work.
  // A tile's rays are set up together, and where they can first and last
  // meet a visible macrocell found once for all of them (tile_start.h).
  struct TileRays {
    RaySetup rays[kTileSize * kTileSize];
    int x0 = 0, y0 = 0, width = 0;
    kernel::TileSpan span;
  };
  RenderStats counted;
  renderTileRuns<TileRays>(
      image, options, pool,
      [&](int x0, int y0, int x1, int y1, TileRays& tile) {
        tile.x0 = x0;
        tile.y0 = y0;
        tile.width = x1 - x0;
        int n = 0;
        for (int y = y0; y < y1; ++y)
          for (int x = x0; x < x1; ++x)
            tile.rays[n++] = shaded ? raySetup(camera.ray(x, y), grid, step, lightWorld)
                                    : raySetup(camera.ray(x, y), grid, step);
        tile.span = kernel::tileSpan(p, tile.rays, n, MacrocellGrid::kShift);
      },
      [&](const TileRays& tile, int x, int y, int n, RayResult* out) {
        cast(p, &tile.rays[(y - tile.y0) * tile.width + (x - tile.x0)], n, MacrocellGrid::kShift, tile.span, out);
      },
      counted);
  if (stats) {
    *stats = counted;
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  }
  return image;
}

}  // namespace pvr::core
