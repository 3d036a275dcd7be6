// The dedicated caching cluster of paper 003 (section 7): the ranks of a
// cache cluster (`set -cluster m,N`) read the time steps' bricks for the
// render clusters they serve (layout.h: render cluster j of a group goes to
// cache cluster j mod M of that group), with the same k-d tree, hold them
// within their budget (runtime.cachemem per cache rank), read the upcoming
// ones ahead, and send each render rank its brick by MPI when the step it
// shows changes. Render rank i of a served cluster of n ranks is served by
// rank i mod m of its cache cluster of m ranks; after the first step, read
// when the dataset loads, the render ranks read nothing from disk.
//
// It serves with a kd decomposition and a format that reads a box alone
// (the trees of both sides are then the same pure function of the grid);
// otherwise the render ranks read their steps themselves.
//
// Both sides decide alike whether a brick travels: the cache rank keeps,
// per render rank it serves, the step that rank shows.
#pragma once

#include <memory>
#include <vector>

#include "node.h"

namespace pvr::node {

// True when `render` (a render cluster) gets its steps from a cache cluster.
bool servedByCacheCluster(const NodeState& state, const ClusterPlan& render);

// Cache ranks, after the bricks load: one brick cache per render rank
// served, each showing the scene's timestep (read there by the render ranks).
void prepareCacheRank(NodeState& state);

// Cache ranks: every render rank of render cluster `renderCluster` that I
// serve and that shows another step gets the brick of `step`; then the
// steps in `upcoming` are read ahead for them. A failure travels to the
// render rank in place of the brick.
void serveStep(NodeState& state, int renderCluster, int step, const std::vector<int>& upcoming);

// Render ranks of a served cluster: the brick of `step` from my cache rank
// (collective over my render cluster: every rank throws the first failure).
std::shared_ptr<ReadyBrick> receiveStep(NodeState& state, int step);

}  // namespace pvr::node
