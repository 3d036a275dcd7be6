// Radix-k compositing (Peterka et al. 2009) on the k-d tree's swap rounds.
//
// Binary swap resolves one bit of the active index per round; radix-k
// resolves log2(k) bits at once: the k ranks of a group (a depth-log2(k)
// subtree of the swap tree) cut their common region into k pieces, every
// member sends every other member that member's piece (direct send inside
// the group), and each blends the k pieces of its own in the group's
// visibility order. Fewer rounds, more messages per round; k = 2 is binary
// swap, same partners, same regions. Extra ranks of a non-power-of-two
// count fold first, as in binary swap. Reads StrategyParams::radix.
#include <algorithm>

#include "pieces.h"

namespace pvr::composite {

namespace {

constexpr int kFoldTag = 1;
constexpr int kFirstRoundTag = 10;

class RadixK final : public Strategy {
 public:
  explicit RadixK(int k) : k_(k) {
    radixKSchedule(swapTree(splitTopology(1)), 0, k);  // validates k before any message
  }

  CompositeResult composite(const core::Image& partial, const core::KdTree& tree,
                            const core::Camera& camera, Communicator& comm,
                            const CompositeOptions& options) const override {
    checkCompositeCall(tree, comm, options);
    const SwapTree swap = swapTree(topologyOf(tree));
    const RadixKSchedule schedule = radixKSchedule(swap, comm.rank(), k_);
    CompositeStats stats;
    PieceChannel channel(comm, options.codec, stats);

    core::Image mine = cropped(partial, activeBounds(partial, partial.rect()));
    runReduceSteps(channel, mine, schedule.fold, tree, camera, kFoldTag);

    auto leftInFront = [&](int node) { return tree.leftInFront(node, camera); };
    core::PixelRect region{0, 0, camera.width(), camera.height()};
    for (std::size_t round = 0; round < schedule.rounds.size(); ++round) {
      const RadixRound& r = schedule.rounds[round];
      // Every other member gets its piece of my image; I get mine from each.
      std::vector<std::pair<int, core::PixelRect>> gives;
      std::vector<int> from;
      for (int d = 0; d < int(r.members.size()); ++d) {
        if (d == r.digit) continue;
        const int rank = swap.actives[std::size_t(r.members[std::size_t(d)])];
        gives.emplace_back(rank, pieceOf(region, d, r.bits));
        from.push_back(rank);
      }
      const std::vector<core::Image> pieces = channel.exchange(kFirstRoundTag + int(round), mine, gives, from);

      // Blend the group's pieces of my region front to back.
      Stopwatch compute;
      const core::PixelRect keep = pieceOf(region, r.digit, r.bits);
      const core::Image own = cropped(mine, activeBounds(mine, keep));
      std::vector<std::pair<int, const core::Image*>> layers;  // (active index, piece)
      for (std::size_t i = 0, d = 0; d < r.members.size(); ++d) {
        if (int(d) == r.digit)
          layers.emplace_back(r.members[d], &own);
        else
          layers.emplace_back(r.members[d], &pieces[i++]);
      }
      std::sort(layers.begin(), layers.end(), [&](const auto& a, const auto& b) {
        return activeInFront(swap, a.first, b.first, leftInFront);
      });
      core::Image blended(camera.width(), camera.height(), {});
      for (const auto& layer : layers) blend(blended, *layer.second, false);
      mine = std::move(blended);
      region = keep;
      stats.computeSeconds += compute.seconds();
    }
    return finishComposite(channel, std::move(mine), schedule.active ? region : core::PixelRect{},
                           swap.actives, camera, options);
  }

 private:
  int k_;
};

}  // namespace

std::unique_ptr<Strategy> makeRadixK(const StrategyParams& params) {
  return std::make_unique<RadixK>(params.radix);
}

}  // namespace pvr::composite
