// report_cache: each render and cache rank's brick caches (brick_cache.h,
// cache_cluster.h) for "performance cache": hits, misses, bytes and steps
// held, read-ahead seconds (wall and CPU), by world rank, and the budget. The master keeps the answer in
// state.reply; docs/protocol.md lists the keys.
#include "table.h"

namespace pvr::node::actions {

void ReportCache::run(NodeState& state, const ReportCache& args) {
  // Four counters per world rank, summed (each rank fills its own row).
  constexpr std::size_t kCounters = 4;
  const std::size_t ranks = std::size_t(state.world.size()), me = std::size_t(state.world.rank());
  std::vector<std::uint64_t> counts(ranks * kCounters, 0);
  std::vector<double> seconds(ranks * 2, 0);  // read-ahead wall and CPU seconds
  // A render rank's own cache; a cache rank's caches of the ranks it serves.
  std::vector<const BrickCache*> caches;
  if (state.renders()) caches.push_back(&state.cache);
  for (const auto& [key, served] : state.served) caches.push_back(served.cache.get());
  for (const BrickCache* cache : caches) {
    const CacheStats s = cache->stats();
    const std::uint64_t row[kCounters] = {s.hits, s.misses, s.bytesHeld, s.stepsHeld};
    for (std::size_t k = 0; k < kCounters; ++k) counts[me * kCounters + k] += row[k];
    seconds[me * 2] += s.readAheadSeconds;
    seconds[me * 2 + 1] += s.readAheadCpuSeconds;
  }
  state.world.allReduceSum(counts);
  state.world.allReduceMax(seconds);
  if (state.world.rank() != 0) return;
  nlohmann::json perRank = nlohmann::json::array();
  for (std::size_t c = 0; c < state.layout.clusters.size(); ++c) {
    const ClusterPlan& plan = state.layout.clusters[c];
    const bool caches = plan.role == proto::ClusterRole::kRender || plan.role == proto::ClusterRole::kCache;
    if ((args.cluster >= 0 && std::size_t(args.cluster) != c) || !caches) continue;
    for (int r : plan.ranks) {
      const std::size_t i = std::size_t(r);
      perRank.push_back({{"rank", r}, {"cluster", c}, {"role", roleName(plan.role)}, {"hits", counts[i * kCounters]},
                         {"misses", counts[i * kCounters + 1]}, {"bytes", counts[i * kCounters + 2]},
                         {"steps", counts[i * kCounters + 3]}, {"read_ahead_s", seconds[i * 2]},
                         {"read_ahead_cpu_s", seconds[i * 2 + 1]}});
    }
  }
  state.reply = {{"ranks", perRank}, {"budget_bytes", cacheBudgetBytes(state.settings)}};
}

}  // namespace pvr::node::actions
