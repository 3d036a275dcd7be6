// SceneRenderer: the volumes of a scene in one process, mixed.
//
// Each scene volume is a whole-volume brick with its own grid and its own
// transfer function. A scene with one visible volume renders through that
// volume's BrickRenderer, bit for bit as a one-volume scene always has;
// with several, every ray is cut at each volume's entry and exit and the
// overlapping media mix exactly (mix_kernel.h, docs/scene.md "Several
// volumes"). Invisible volumes cost nothing.
//
// Pre-integration applies to one visible volume; several are point-sampled
// (each segment's samples mix plain extinction tables), whatever
// options.preintegrated says. A brick of a decomposed scene takes the
// same path for the same visible volumes as the whole does.
#pragma once

#include <memory>
#include <vector>

#include "../brick.h"
#include "../camera.h"
#include "../image.h"
#include "../region.h"
#include "../scene.h"
#include "../thread_pool.h"
#include "../transfer.h"
#include "raycaster.h"

namespace pvr::core {

class SceneRenderer {
 public:
  // volumes[i] is the whole volume of scene volume i (stored box = the
  // whole grid); each must outlive the renderer. Builds each one's
  // macrocells, over the pool when given.
  explicit SceneRenderer(const std::vector<const Brick*>& volumes, ThreadPool* pool = nullptr);

  // One brick of a scene decomposed over its volumes' union
  // (decompose/union_regions.h): renders only the parts of rays whose
  // midpoints lie in `region`, so the bricks of a decomposition rendered
  // apart and composited in visibility order equal the whole. grids[i] is
  // volume i's grid; bricks[i] holds at least volumeBoxFor(grids[i],
  // region, step) of it for every step it is classified with, or is null
  // where that box is empty (the volume is far from the region, and only
  // its domain's faces matter here).
  SceneRenderer(const std::vector<const Brick*>& bricks, const std::vector<GridGeometry>& grids,
                const WorldRegion& region, ThreadPool* pool = nullptr);

  // Classifies each volume by the scene's entry of the same index (its
  // transfer function, resolved, and visibility); `volumes` has one entry
  // per brick. Call on every transfer-function, visibility, step or
  // skipping change. Throws Error kInvalidArgument for more than
  // kMaxMixedVolumes visible volumes.
  void classify(const std::vector<SceneVolume>& volumes, const RenderOptions& options,
                ThreadPool* pool = nullptr);

  // As BrickRenderer::render, over the union of the visible volumes'
  // screen rectangles. `options` must match the last classify() in step
  // and pre-integration.
  Image render(const Camera& camera, const RenderOptions& options, ThreadPool& pool,
               RenderStats* stats = nullptr, const PixelRect* region = nullptr) const;

  // Visible volumes, by index into the scene's list.
  const std::vector<int>& shown() const { return shown_; }

 private:
  Image renderMixed(const Camera& camera, const RenderOptions& options, ThreadPool& pool,
                    RenderStats* stats, const PixelRect* region) const;

  struct Layer {
    GridGeometry grid;
    const Brick* brick = nullptr;  // null: no data near the region
    std::unique_ptr<BrickRenderer> renderer;  // macrocells, and the one-volume path
    ExtinctionTable extinction;               // the mixed path's table
  };
  std::vector<Layer> layers_;
  WorldRegion region_;
  std::vector<int> shown_;
  double classifiedStep_ = 0;
  bool classifiedPreintegrated_ = false;
};

}  // namespace pvr::core
