#include "cache_cluster.h"

#include <algorithm>
#include <cstring>
#include <utility>

#include "preprocess.h"
#include "wave_io.h"

namespace pvr::node {

namespace {

// My position in my cluster's ranks.
int indexInCluster(const NodeState& state) {
  const std::vector<int>& ranks = state.myCluster()->ranks;
  return int(std::find(ranks.begin(), ranks.end(), state.world.rank()) - ranks.begin());
}

}  // namespace

bool servedByCacheCluster(const NodeState& state, const ClusterPlan& render) {
  return render.cacheCluster >= 0 && state.source && !state.several() && state.source->canReadPartially() &&
         state.settings.decomposition != Decomposition::kBalanced;
}

void prepareCacheRank(NodeState& state) {
  state.served.clear();
  const ClusterPlan* me = state.myCluster();
  if (!me || me->role != proto::ClusterRole::kCache || !state.source) return;
  const int m = int(me->ranks.size()), mine = indexInCluster(state);
  std::vector<std::pair<int, int>> keys;
  for (int c : me->serves) {
    const ClusterPlan& render = state.layout.clusters[std::size_t(c)];
    if (!servedByCacheCluster(state, render)) continue;
    const int n = int(render.ranks.size());
    const core::KdTree tree = core::KdTree::build(state.source->grid(), n, splitAxisRule(state.settings.decomposition));
    for (int i = mine; i < n; i += m) {
      NodeState::ServedRank& s = state.served[{c, i}];
      s.cache = std::make_unique<BrickCache>();
      const core::NodeBox stored = core::storedBox(tree, i, state.ghost);
      s.cache->reset(
          [source = state.source.get(), owned = tree.ownedBox(i), stored](int step) {
            return source->step(step).readBox(owned, stored);
          },
          [source = state.source.get(), stored](int step) { source->step(step).prefetchBox(stored); });
      s.shown = state.scene.volumes.front().source.timestep;
      keys.push_back({c, i});
    }
  }
  // The budget is the rank's: shared by the render ranks it serves.
  for (const auto& key : keys)
    state.served[key].cache->setBudget(cacheBudgetBytes(state.settings) / std::max<std::size_t>(1, keys.size()));
}

void serveStep(NodeState& state, int renderCluster, int step, const std::vector<int>& upcoming) {
  const ClusterPlan& render = state.layout.clusters[std::size_t(renderCluster)];
  for (auto& [key, s] : state.served) {
    if (key.first != renderCluster) continue;
    if (s.shown != step) {
      comm::Bytes bytes;
      try {
        const std::shared_ptr<ReadyBrick> ready = s.cache->take(step);
        bytes = comm::encodeFailure(std::nullopt);
        const auto* data = ready->brick.bytes();
        bytes.insert(bytes.end(), data, data + ready->brick.byteSize());
      } catch (...) {
        bytes = comm::encodeFailure(comm::failureOf(std::current_exception(), state.world.rank()));
      }
      state.world.send(render.ranks[std::size_t(key.second)], kStepTag, bytes);
      s.shown = step;
    }
    s.cache->readAhead(upcoming);
  }
}

std::shared_ptr<ReadyBrick> receiveStep(NodeState& state, int step) {
  const ClusterPlan& me = *state.myCluster();
  const ClusterPlan& cache = state.layout.clusters[std::size_t(me.cacheCluster)];
  const int i = indexInCluster(state);
  const comm::Bytes bytes = state.world.receive(cache.ranks[std::size_t(i) % cache.ranks.size()], kStepTag);
  std::shared_ptr<ReadyBrick> ready;
  comm::runAgreed(*state.clusterComm, [&] {
    if (auto failure = comm::decodeFailure(bytes)) throw comm::FailureError(*failure);
    core::Brick brick(state.source->grid(), state.source->type(), state.tree->ownedBox(i),
                      core::storedBox(*state.tree, i, state.ghost));
    if (bytes.size() - 1 != brick.byteSize())
      throw Error(ErrorCode::kInternal, "cache cluster: step " + std::to_string(step) + " came with " +
                                            std::to_string(bytes.size() - 1) + " bytes, expected " +
                                            std::to_string(brick.byteSize()));
    std::memcpy(brick.bytes(), bytes.data() + 1, brick.byteSize());
    // Range and macrocell bounds, without the histogram's counts: a step
    // the session moves to is counted when its histogram is agreed (data.cpp).
    core::Preprocessed p = core::preprocessVoxels(brick.type(), brick.owned(), brick.stored(),
                                                  std::as_const(brick).bytes(), state.pool.get());
    brick.setPreprocessed(p.range, std::move(p.bounds), nullptr);
    ready = makeReady(std::move(brick), step);
  });
  return ready;
}

}  // namespace pvr::node
