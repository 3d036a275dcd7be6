#include "scene_renderer.h"

#include <chrono>
#include <string>

#include "../decompose/union_regions.h"
#include "../error.h"
#include "kernel_setup.h"
#include "mix_kernel.h"
#include "tiles.h"

namespace pvr::core {

SceneRenderer::SceneRenderer(const std::vector<const Brick*>& volumes, ThreadPool* pool) {
  if (volumes.empty()) throw Error(ErrorCode::kInvalidArgument, "SceneRenderer: a scene has at least one volume");
  for (const Brick* brick : volumes) {
    if (brick->stored() != brick->grid().allNodes())
      throw Error(ErrorCode::kInvalidArgument, "SceneRenderer: a volume stores " + toString(brick->stored()) +
                                                   ", not its whole grid " + toString(brick->grid().allNodes()));
    Layer layer;
    layer.grid = brick->grid();
    layer.brick = brick;
    layer.renderer = std::make_unique<BrickRenderer>(*brick, pool);
    layers_.push_back(std::move(layer));
  }
}

SceneRenderer::SceneRenderer(const std::vector<const Brick*>& bricks, const std::vector<GridGeometry>& grids,
                             const WorldRegion& region, ThreadPool* pool)
    : region_(region) {
  if (bricks.empty() || bricks.size() != grids.size())
    throw Error(ErrorCode::kInvalidArgument, "SceneRenderer: " + std::to_string(bricks.size()) + " bricks for " +
                                                 std::to_string(grids.size()) + " volumes");
  for (std::size_t i = 0; i < bricks.size(); ++i) {
    Layer layer;
    layer.grid = grids[i];
    layer.brick = bricks[i];
    if (layer.brick) {
      layer.renderer = std::make_unique<BrickRenderer>(*layer.brick, pool);
      if (!region.unbounded()) layer.renderer->restrictTo(region);
    }
    layers_.push_back(std::move(layer));
  }
}

void SceneRenderer::classify(const std::vector<SceneVolume>& volumes, const RenderOptions& options,
                             ThreadPool* pool) {
  if (volumes.size() != layers_.size())
    throw Error(ErrorCode::kInternal, "SceneRenderer::classify: " + std::to_string(volumes.size()) +
                                          " scene volumes for " + std::to_string(layers_.size()) + " bricks");
  shown_.clear();
  for (std::size_t i = 0; i < volumes.size(); ++i)
    if (volumes[i].visible) shown_.push_back(int(i));
  if (shown_.size() > std::size_t(kMaxMixedVolumes))
    throw Error(ErrorCode::kInvalidArgument, "volumes: " + std::to_string(shown_.size()) +
                                                 " are visible; at most " + std::to_string(kMaxMixedVolumes) +
                                                 " mix in one rendering");
  // One volume: its own renderer as configured. Several: plain tables for
  // the macrocells (pre-integration does not mix) and extinction tables.
  RenderOptions own = options;
  if (shown_.size() > 1) own.preintegrated = false;
  // The step per region is for one volume alone; a scene of several keeps
  // its step in every brick, visible or not (raycaster.h, targetPsnr).
  if (volumes.size() > 1) own.targetPsnr = 0;
  for (int i : shown_) {
    Layer& layer = layers_[i];
    if (!layer.brick) continue;
    // A brick must hold what the pieces it owns read at this step.
    const NodeBox needed = volumeBoxFor(layer.grid, region_, options.step);
    if (!region_.unbounded() && !layer.brick->stored().contains(needed))
      throw Error(ErrorCode::kInternal, "SceneRenderer::classify: volume '" + volumes[i].name + "' stores " +
                                            toString(layer.brick->stored()) + ", not the " + toString(needed) +
                                            " its region needs at step " + std::to_string(options.step));
    layer.renderer->classify(volumes[i].transfer, own, pool);
    if (shown_.size() > 1) layer.extinction = ExtinctionTable(volumes[i].transfer, options.step);
  }
  classifiedStep_ = options.step;
  classifiedPreintegrated_ = options.preintegrated;
}

Image SceneRenderer::render(const Camera& camera, const RenderOptions& options, ThreadPool& pool,
                            RenderStats* stats, const PixelRect* region) const {
  if (options.step != classifiedStep_ || options.preintegrated != classifiedPreintegrated_)
    throw Error(ErrorCode::kInternal, "SceneRenderer::render: classify() was called with other options");
  if (shown_.size() == 1) {
    const Layer& only = layers_[shown_.front()];
    if (only.renderer) return only.renderer->render(camera, options, pool, stats, region);
    if (stats) *stats = {};
    return Image(camera.width(), camera.height(), PixelRect{});
  }
  return renderMixed(camera, options, pool, stats, region);
}

Image SceneRenderer::renderMixed(const Camera& camera, const RenderOptions& options, ThreadPool& pool,
                                 RenderStats* stats, const PixelRect* region) const {
  const auto started = std::chrono::steady_clock::now();
  // The volumes with cells, their kernel parameters and the union of their
  // screen rectangles.
  const std::vector<float> specular = specularTable(options.shading.shininess);
  MixedVolume volumes[kMaxMixedVolumes];
  const GridGeometry* grids[kMaxMixedVolumes];
  int n = 0;
  PixelRect rect;
  for (int i : shown_) {
    const Layer& layer = layers_[i];
    const GridGeometry& grid = layer.grid;
    if (grid.dims.x < 2 || grid.dims.y < 2 || grid.dims.z < 2) continue;  // no cells: nothing to show
    MixedVolume& v = volumes[n];
    grids[n] = &grid;
    ++n;
    if (!layer.brick) {
      // No data near the region: its domain's faces still cut the rays.
      v = MixedVolume{};
      for (int a = 0; a < 3; ++a) v.params.domainMax[a] = float(grid.dims[a] - 1);
      continue;
    }
    setBrick(v.params, *layer.brick, layer.renderer->macrocells());
    v.params.table = layer.extinction.entries();
    v.params.tableEntries = ExtinctionTable::kEntries;
    v.params.tableScale = layer.extinction.scale();
    v.params.tableOffset = layer.extinction.offset();
    setOptions(v.params, options, specular.data());
    v.sample = pickMixSampler(layer.brick->type(), options.shading.enabled);
    // The region's part of the domain on screen.
    Vec3 lo = grid.domainMin(), hi = grid.domainMax();
    bool empty = false;
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(lo[a], region_.lo[a]);
      hi[a] = std::min(hi[a], region_.hi[a]);
      empty |= lo[a] > hi[a];
    }
    if (empty) continue;
    const PixelRect r = camera.project(lo, hi);
    rect = rect.empty() ? r : rect.unite(r);
  }
  if (region) rect = rect.intersect(*region);
  Image image(camera.width(), camera.height(), rect);
  if (n == 0 || image.rect().empty()) {
    if (stats) *stats = {};
    return image;
  }

  const Vec3 lightWorld = normalize(camera.toWorld(options.shading.lightDirection));
  const float earlyTermination = float(std::clamp(options.earlyTermination, 0.0, 1.0));
  RenderStats counted;
  const bool bounded = !region_.unbounded();
  renderTiles(image, options, pool, [&](int x, int y) {
    const Ray ray = camera.ray(x, y);
    RaySetup rays[kMaxMixedVolumes];
    for (int i = 0; i < n; ++i) rays[i] = raySetup(ray, *grids[i], options.step, lightWorld);
    if (!bounded) return castMixedRay(volumes, rays, n, earlyTermination, MacrocellGrid::kShift);
    MixOwnership own;
    for (int a = 0; a < 3; ++a) {
      own.origin[a] = ray.origin[a];
      own.step[a] = ray.direction[a] * options.step;
      own.lo[a] = region_.lo[a];
      own.hi[a] = region_.hi[a];
    }
    return castMixedRay(volumes, rays, n, earlyTermination, MacrocellGrid::kShift, &own);
  }, counted);
  if (stats) {
    *stats = counted;
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  }
  return image;
}

}  // namespace pvr::core
