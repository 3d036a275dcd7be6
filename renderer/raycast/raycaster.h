// The per-brick ray caster.
//
// A BrickRenderer renders one brick (a whole volume is one brick) into the
// screen rectangle its owned box projects to. Samples lie at t = k * h along
// each camera ray, the same for every brick, and a sample belongs to exactly
// one brick (owned boxes are half-open where bricks meet), so bricks
// rendered apart and composited front to back equal the whole. Each sample
// stands for one step of the ray; the first and last samples of the ray's
// chord through the domain stand for the stretch to the domain's faces, so
// the samples cover the chord exactly (kernel.h, ChordEnds).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>

#include "../brick.h"
#include "../camera.h"
#include "../image.h"
#include "../region.h"
#include "../scene.h"
#include "../thread_pool.h"
#include "../transfer.h"
#include "clear_cells.h"
#include "macrocells.h"
#include "step_levels.h"

namespace pvr::core {

struct RenderOptions {
  double step = 0;              // world length h, > 0
  double earlyTermination = 1;  // stop a ray once its opacity reaches this; 1 = off
  bool preintegrated = false;
  // > 0: the step of each region is chosen to meet this PSNR (dB), between
  // step / 8 and 8 step (step_levels.h). Plain sampling of a scene of one
  // volume only: pre-integration and several volumes keep `step`.
  double targetPsnr = 0;
  bool skipEmpty = true;        // macrocell empty-space skipping
  ShadingSpec shading;
  // Checked between tiles, never per sample: once it reads true, tiles not
  // yet started are skipped and render() throws Error kCancelled, so a
  // Cancel stops a long frame within one tile's time.
  const std::atomic<bool>* stop = nullptr;
  // Advanced by one per finished tile: a watchdog's sign that this rank
  // makes progress (node/rank_watch.h).
  std::atomic<std::uint64_t>* tilesDone = nullptr;
};

RenderOptions renderOptionsFor(const Scene& resolvedScene);

// Ghost layers a brick needs beyond its owned box for these options:
// trilinear sampling needs none (neighbours share the face nodes), central
// differences one, a pre-integrated segment reads two steps beyond (its
// back node's curvature correction) and is lit up to a step beyond, one
// more for its central differences; a target PSNR reads the value ranges
// of macrocells a level block's length beyond (levelGhostLayers()).
int ghostLayers(const GridGeometry& grid, const RenderOptions& options);

struct RenderStats {
  std::uint64_t rays = 0;     // rays that met the brick
  std::uint64_t samples = 0;  // samples reconstructed and classified
  double seconds = 0;
};

class BrickRenderer {
 public:
  // Builds the macrocell grid from the brick's bounds, or computes them
  // (over the pool's threads when one is given) if it carries none; the
  // brick must outlive the renderer.
  explicit BrickRenderer(const Brick& brick, ThreadPool* pool = nullptr);

  // (Re)builds the classification tables, macrocell visibility and distance
  // field, over the pool's threads when one is given. Cheap; call on every
  // transfer-function, step or skipping change.
  void classify(const TransferFunctionSpec& tf, const RenderOptions& options, ThreadPool* pool = nullptr);

  // `options` must match the last classify() in step and pre-integration.
  // Renders the brick's screen rectangle, or only its part inside `region`
  // (a band of scanlines, say) when one is given: pixels outside it cost
  // nothing.
  Image render(const Camera& camera, const RenderOptions& options, ThreadPool& pool,
               RenderStats* stats = nullptr, const PixelRect* region = nullptr) const;

  // Renders only the samples whose position lies in `region` instead of
  // those of the brick's owned box: the brick is this volume's part of a
  // rank's region of a several-volume scene (decompose/union_regions.h)
  // and stores at least volumeBoxFor(grid, region, step). Membership is
  // tested in the volume's index space against the region's faces, the
  // same numbers in every brick, so the regions still partition the samples.
  void restrictTo(const WorldRegion& region) { region_ = region; }

  const Brick& brick() const { return brick_; }
  const MacrocellGrid& macrocells() const { return macrocells_; }
  // Seconds the constructor spent computing macrocell bounds: 0 when the
  // brick carried them (its loadTimes().preprocess counted them then).
  double preprocessSeconds() const { return macrocells_.buildSeconds(); }

 private:
  const Brick& brick_;
  MacrocellGrid macrocells_;
  TransferTable table_;
  std::unique_ptr<PreintegratedTable> preintegrated_;
  // Quality chosen by error: the macrocells' levels (kept while the step
  // stays) and one table per level; empty tables when it is off.
  std::unique_ptr<StepLevels> levels_;
  std::vector<TransferTable> levelTables_;
  ClearCells clearCells_;  // of table_, or of preintegrated_ when there is one
  double classifiedStep_ = 0;
  std::optional<WorldRegion> region_;
};

}  // namespace pvr::core
