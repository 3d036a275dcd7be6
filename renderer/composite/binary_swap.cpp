// Binary-swap compositing (Ma, Painter, Hansen, Krogh 1994) on the k-d tree.
//
// In each round two ranks across a split of the tree hold the same region
// of the frame; each keeps one half and sends the other half to its
// partner, then blends what it received in front of or behind its own
// according to which side of the split faces the viewer. After log2(m)
// rounds every active rank holds a finished 1/m of the frame. Every piece
// is cut to the bounding rectangle of its non-empty pixels before it is
// sent or kept, so early rounds (large regions, sparse data) and late
// rounds (small regions, dense data) both stay cheap.
//
// Rank counts that are not powers of two: the n - m extra ranks fold first
// (schedule.h, swapTree): inside each subtree whose share of the m active
// ranks is one, the ranks reduce into the subtree's first rank by the plain
// tree method, then the m active ranks swap. Folded ranks idle after their
// one send. For n a power of two each rank sends exactly log2(n) messages.
#include "pieces.h"

namespace pvr::composite {

namespace {

constexpr int kFoldTag = 1;
constexpr int kFirstSwapTag = 10;

class BinarySwap final : public Strategy {
 public:
  CompositeResult composite(const core::Image& partial, const core::KdTree& tree,
                            const core::Camera& camera, Communicator& comm,
                            const CompositeOptions& options) const override {
    checkCompositeCall(tree, comm, options);
    const SwapTree swap = swapTree(topologyOf(tree));
    const BinarySwapSchedule schedule = binarySwapSchedule(swap, comm.rank());
    CompositeStats stats;
    PieceChannel channel(comm, options.codec, stats);

    // Fold the extra ranks into the active ones.
    core::Image mine = cropped(partial, activeBounds(partial, partial.rect()));
    runReduceSteps(channel, mine, schedule.fold, tree, camera, kFoldTag);

    // Swap halves of the current region with each round's partner.
    core::PixelRect region{0, 0, camera.width(), camera.height()};
    for (std::size_t j = 0; j < schedule.rounds.size(); ++j) {
      const SwapRound& round = schedule.rounds[j];
      const auto [lower, upper] = halve(region);
      const core::PixelRect keep = round.keepLower ? lower : upper;
      const core::PixelRect give = round.keepLower ? upper : lower;
      const core::Image piece = channel.swap(round.partner, kFirstSwapTag + int(j), mine, give);
      Stopwatch compute;
      core::Image kept = cropped(mine, activeBounds(mine, keep));
      const bool pieceInFront = round.inLeft != tree.leftInFront(round.node, camera);
      blend(kept, piece, pieceInFront);
      mine = std::move(kept);
      region = keep;
      stats.computeSeconds += compute.seconds();
    }
    return finishComposite(channel, std::move(mine), schedule.active ? region : core::PixelRect{},
                           swap.actives, camera, options);
  }
};

}  // namespace

std::unique_ptr<Strategy> makeBinarySwap(const StrategyParams&) { return std::make_unique<BinarySwap>(); }

}  // namespace pvr::composite
