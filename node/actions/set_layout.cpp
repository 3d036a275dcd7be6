// set_layout: arranges the ranks into clusters and groups (layout.h); the
// render clusters re-read the dataset, if one is open.
#include "../data.h"
#include "table.h"

namespace pvr::node::actions {

void SetLayout::run(NodeState& state, const SetLayout& args) {
  // The clusters re-read the data: the longer stall limit applies.
  const comm::LivenessScope loading(state.liveness, comm::LivenessScope::Kind::kLoading);
  // The same pure function on every rank: the same layout or the same error.
  Layout layout = makeLayout(args.clusters, state.world.size());
  dropData(state);
  state.layout = std::move(layout);
  state.cluster = state.layout.clusterOfRank[std::size_t(state.world.rank())];
  state.clusterComm.reset();
  if (state.cluster >= 0) state.clusterComm = std::make_unique<comm::SubCommunicator>(state.world, state.myCluster()->ranks);
  state.compositeLog = {};
  loadBricks(state);
}

}  // namespace pvr::node::actions
