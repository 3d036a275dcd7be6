// report_memory: dataset bytes each rank holds (its brick: owned nodes plus
// ghost layers), per cluster. The master keeps the answer in state.reply
// for "performance memory cluster".
#include "table.h"

namespace pvr::node::actions {

void ReportMemory::run(NodeState& state, const ReportMemory& args) {
  std::vector<std::uint64_t> bytes(std::size_t(state.world.size()), 0);
  // Ranks without a brick (composite clusters, a dedicated collector) hold none.
  bytes[std::size_t(state.world.rank())] = state.current ? state.current->bytes() : 0;
  state.world.allReduceSum(bytes);
  if (state.world.rank() != 0) return;
  const int only = args.cluster;
  nlohmann::json clusters = nlohmann::json::array();
  for (std::size_t c = 0; c < state.layout.clusters.size(); ++c) {
    if (only >= 0 && std::size_t(only) != c) continue;
    const ClusterPlan& plan = state.layout.clusters[c];
    std::uint64_t total = 0, most = 0;
    nlohmann::json perRank = nlohmann::json::array();
    for (int r : plan.ranks) {
      total += bytes[std::size_t(r)];
      most = std::max(most, bytes[std::size_t(r)]);
      perRank.push_back(bytes[std::size_t(r)]);
    }
    clusters.push_back({{"index", c}, {"role", roleName(plan.role)}, {"group", plan.groupId},
                        {"ranks", plan.ranks.size()}, {"bytes", total}, {"bytes_per_rank_max", most},
                        {"bytes_per_rank", perRank}, {"world_ranks", plan.ranks}});
  }
  std::uint64_t volumeBytes = 0;
  if (state.source)
    for (const core::VolumeSource* source : state.sources())  // every volume of the scene
      volumeBytes += std::uint64_t(source->grid().allNodes().nodeCount()) * core::scalarSize(source->type());
  state.reply = {{"clusters", clusters}, {"volume_bytes", volumeBytes}, {"ghost_layers", state.ghost}};
}

}  // namespace pvr::node::actions
