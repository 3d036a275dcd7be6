// The image work every strategy shares: cutting a region's non-empty part,
// blending two pieces in depth order, moving pieces through the
// communicator as sparse codes while counting bytes and time, and the final
// gather of tiles at the root.
#pragma once

#include <chrono>
#include <utility>
#include <vector>

#include "schedule.h"
#include "strategy.h"

namespace pvr::composite {

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

// The bounding rectangle of the non-empty pixels of `image` inside `within`
// (the paper's bounding rectangle: only it is stored, sent and blended).
core::PixelRect activeBounds(const core::Image& image, const core::PixelRect& within);
// A copy of the part of `image` inside `rect`, its frame unchanged.
core::Image cropped(const core::Image& image, const core::PixelRect& rect);
// accum = other over accum (otherInFront) or accum over other. accum's
// rectangle grows to the bounding rectangle of both.
void blend(core::Image& accum, const core::Image& other, bool otherInFront);

// Sends and receives pieces of images for one composite, adding to `stats`.
class PieceChannel {
 public:
  PieceChannel(Communicator& comm, core::ImageCodec codec, CompositeStats& stats)
      : comm_(comm), codec_(codec), stats_(stats) {}

  Communicator& comm() { return comm_; }
  CompositeStats& stats() { return stats_; }

  // The non-empty part of `image` inside `region`, encoded; counted as one
  // compositing message to be sent.
  Bytes encode(const core::Image& image, const core::PixelRect& region);
  core::Image decode(std::span<const std::byte> bytes);

  void send(int to, int tag, const core::Image& image, const core::PixelRect& region);
  core::Image receive(int from, int tag);
  // Gives `partner` my part inside `give` and returns its part for me.
  core::Image swap(int partner, int tag, const core::Image& image, const core::PixelRect& give);
  // Sends each (rank, region) its part of `image`, receives one piece from
  // each rank of `from` (in that order).
  std::vector<core::Image> exchange(int tag, const core::Image& image,
                                    const std::vector<std::pair<int, core::PixelRect>>& gives,
                                    const std::vector<int>& from);

 private:
  Communicator& comm_;
  core::ImageCodec codec_;
  CompositeStats& stats_;
};

// Runs tree-reduction steps (schedule.h) on `mine`: receives and blends
// the right subtree's image, or sends mine and clears it. Returns false
// once this rank has sent its image away.
bool runReduceSteps(PieceChannel& channel, core::Image& mine, const std::vector<ReduceStep>& steps,
                    const core::KdTree& tree, const core::Camera& camera, int tag);

// Ends a composite: `mine` holds this rank's finished pixels of `tile`
// (empty tile: a rank that holds nothing). With kGatherAtRoot, every owner
// in `owners` (the ranks holding tiles) sends its tile to the root, which
// returns the whole frame; with kTiles each rank returns its own tile.
CompositeResult finishComposite(PieceChannel& channel, core::Image mine, const core::PixelRect& tile,
                                const std::vector<int>& owners, const core::Camera& camera,
                                const CompositeOptions& options);

// Checks what every rank can check alike (so all throw together, before
// any message): the tree's rank count and the root.
void checkCompositeCall(const core::KdTree& tree, const Communicator& comm,
                        const CompositeOptions& options);

}  // namespace pvr::composite
