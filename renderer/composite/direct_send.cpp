// Direct-send compositing (Hsu; Neumann): the frame is cut into one tile
// per rank (partitionFrame: like the tree, across the longer side), every
// rank sends each tile owner the non-empty part of its image inside that
// tile, in one round, and each owner blends what it received front to back
// in the tree's visibility order.
//
// Owners must know whom to expect, so the ranks first share the bounding
// rectangles of their images (one small allGather, not counted as
// compositing messages); a rank sends only to tiles its rectangle meets,
// at most n - 1 messages, against log2(n) larger ones for binary swap.
#include <cstring>

#include "pieces.h"

namespace pvr::composite {

namespace {

constexpr int kPieceTag = 1;

Bytes rectBytes(const core::PixelRect& r) {
  Bytes out(sizeof r);
  std::memcpy(out.data(), &r, sizeof r);
  return out;
}

core::PixelRect rectFrom(const Bytes& bytes) {
  core::PixelRect r;
  if (bytes.size() != sizeof r) throw Error(ErrorCode::kInternal, "direct send: bad rectangle message");
  std::memcpy(&r, bytes.data(), sizeof r);
  return r;
}

class DirectSend final : public Strategy {
 public:
  CompositeResult composite(const core::Image& partial, const core::KdTree& tree,
                            const core::Camera& camera, Communicator& comm,
                            const CompositeOptions& options) const override {
    checkCompositeCall(tree, comm, options);
    CompositeStats stats;
    PieceChannel channel(comm, options.codec, stats);
    const int me = comm.rank();
    const std::vector<core::PixelRect> tiles =
        partitionFrame({0, 0, camera.width(), camera.height()}, topologyOf(tree));
    const core::Image mine = cropped(partial, activeBounds(partial, partial.rect()));

    // Share bounding rectangles so every owner knows its senders.
    Stopwatch share;
    const std::vector<Bytes> rects = comm.allGather(rectBytes(mine.rect()));
    stats.communicationSeconds += share.seconds();

    // Send every tile its part of my image; receive my tile's parts.
    std::vector<std::pair<int, core::PixelRect>> gives;
    std::vector<int> from;
    for (int r = 0; r < comm.size(); ++r) {
      if (r == me) continue;
      if (!mine.rect().intersect(tiles[std::size_t(r)]).empty()) gives.emplace_back(r, tiles[std::size_t(r)]);
      if (!rectFrom(rects[std::size_t(r)]).intersect(tiles[std::size_t(me)]).empty()) from.push_back(r);
    }
    std::vector<core::Image> pieces = channel.exchange(kPieceTag, mine, gives, from);

    // Blend front to back: everything that comes later lies behind.
    Stopwatch compute;
    std::vector<const core::Image*> byRank(std::size_t(comm.size()), nullptr);
    for (std::size_t i = 0; i < from.size(); ++i) byRank[std::size_t(from[i])] = &pieces[i];
    const core::Image own = cropped(mine, tiles[std::size_t(me)]);
    byRank[std::size_t(me)] = &own;
    core::Image tile(camera.width(), camera.height(), {});
    for (int r : tree.visibilityOrder(camera))
      if (byRank[std::size_t(r)]) blend(tile, *byRank[std::size_t(r)], false);
    stats.computeSeconds += compute.seconds();

    std::vector<int> owners(std::size_t(comm.size()));
    for (int r = 0; r < comm.size(); ++r) owners[std::size_t(r)] = r;
    return finishComposite(channel, std::move(tile), tiles[std::size_t(me)], owners, camera, options);
  }
};

}  // namespace

std::unique_ptr<Strategy> makeDirectSend(const StrategyParams&) { return std::make_unique<DirectSend>(); }

}  // namespace pvr::composite
