// The tile loop every caster shares: 16x16 tiles of an image's rectangle
// over a pool, cancellation between tiles, progress and work counts.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>

#include "../error.h"
#include "../image.h"
#include "../thread_pool.h"
#include "kernel.h"
#include "raycaster.h"

namespace pvr::core {

inline constexpr int kTileSize = 16;

// For each tile [x0, x1) x [y0, y1) of image.rect(), calls
// beginTile(x0, y0, x1, y1, tile) on a Tile of the worker's own (what the
// tile's rays share), then castRun(tile, x, y, n, out) for runs of
// n <= kRaysAtOnce pixels (x, y), (x + 1, y), ... of each of its rows,
// which fills out[0, n), and stores their colours; adds up samples and the
// rays that hit into `stats` (seconds are the caller's). Throws Error
// kCancelled once options.stop reads true (tiles not yet started are
// skipped).
template <typename Tile, typename BeginTile, typename CastRun>
void renderTileRuns(Image& image, const RenderOptions& options, ThreadPool& pool, const BeginTile& beginTile,
                    const CastRun& castRun, RenderStats& stats) {
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
    Tile state;
    beginTile(x0, y0, x1, y1, state);
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; x += kRaysAtOnce) {
        const int n = std::min(kRaysAtOnce, x1 - x);
        RayResult res[kRaysAtOnce];
        castRun(state, x, y, n, res);
        for (int i = 0; i < n; ++i) {
          image.at(x + i, y) = res[i].colour;
          samples += res[i].samples;
          rays += res[i].hit ? 1 : 0;
        }
      }
    }
    totalSamples += samples;
    totalRays += rays;
    if (options.tilesDone) options.tilesDone->fetch_add(1, std::memory_order_relaxed);
  });
  if (stopped()) throw Error(ErrorCode::kCancelled, "cancelled");
  stats.samples = totalSamples;
  stats.rays = totalRays;
}

// renderTileRuns for a caster of one pixel at a time: castPixel(x, y) -> RayResult.
template <typename CastPixel>
void renderTiles(Image& image, const RenderOptions& options, ThreadPool& pool, const CastPixel& castPixel,
                 RenderStats& stats) {
  struct NoTile {};
  renderTileRuns<NoTile>(
      image, options, pool, [](int, int, int, int, NoTile&) {},
      [&](NoTile&, int x, int y, int n, RayResult* out) {
        for (int i = 0; i < n; ++i) out[i] = castPixel(x + i, y);
      },
      stats);
}

}  // namespace pvr::core
