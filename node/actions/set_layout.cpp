// set_layout {"clusters": [[role, ranks, group], ...]}: arranges the ranks
// into clusters and groups (layout.h); the clusters re-read the dataset.
#include "../data.h"
#include "../node.h"

namespace pvr::node::actions {

void setLayout(NodeState& state, const ActionArgs& args) {
  std::vector<proto::ClusterSpec> specs;
  for (const auto& c : args.at("clusters"))
    specs.push_back({proto::ClusterRole(c.at(0).get<int>()), c.at(1).get<std::uint32_t>(), c.at(2).get<std::uint32_t>()});
  // The same pure function on every rank: the same layout or the same error.
  Layout layout = makeLayout(specs, state.world.size());
  dropData(state);
  state.layout = std::move(layout);
  state.cluster = state.layout.clusterOfRank[std::size_t(state.world.rank())];
  state.clusterComm.reset();
  if (state.cluster >= 0) state.clusterComm = std::make_unique<comm::SubCommunicator>(state.world, state.myCluster()->ranks);
  state.compositeLog = {};
  distributeData(state);
}

}  // namespace pvr::node::actions
