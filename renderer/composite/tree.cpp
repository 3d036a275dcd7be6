// Binary-tree compositing: the naive method the binary-swap paper improves
// on. Up the k-d tree, the first rank of each right subtree sends its whole
// composite image to the first rank of the left subtree, which blends it in
// front or behind. Half the ranks fall idle at every level, and rank 0 does
// the last full-frame blend alone; kept as the baseline.
#include "pieces.h"

namespace pvr::composite {

namespace {

constexpr int kReduceTag = 1;

class TreeReduce final : public Strategy {
 public:
  CompositeResult composite(const core::Image& partial, const core::KdTree& tree,
                            const core::Camera& camera, Communicator& comm,
                            const CompositeOptions& options) const override {
    checkCompositeCall(tree, comm, options);
    CompositeStats stats;
    PieceChannel channel(comm, options.codec, stats);
    core::Image mine = cropped(partial, activeBounds(partial, partial.rect()));
    const bool holdsAll = runReduceSteps(channel, mine, treeReduceSchedule(topologyOf(tree), comm.rank()),
                                         tree, camera, kReduceTag);
    const core::PixelRect frame{0, 0, camera.width(), camera.height()};
    return finishComposite(channel, std::move(mine), holdsAll ? frame : core::PixelRect{}, {0}, camera,
                           options);
  }
};

}  // namespace

std::unique_ptr<Strategy> makeTree(const StrategyParams&) { return std::make_unique<TreeReduce>(); }

}  // namespace pvr::composite
