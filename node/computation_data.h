// A computation volume on the ranks (docs/steering.md): what data.cpp does
// for it in place of reading bricks. The render clusters each run the
// computation over their k-d decomposition (computations/computation_run.h);
// the brick on screen is its field at the step the session shows, rebuilt
// (value range, macrocells, classification) after each step.
#pragma once

#include <vector>

#include "computations/computation_source.h"
#include "distribute.h"
#include "node.h"

namespace pvr::node {

// The open volume as a computation, or null (none open, or not one).
ComputationSource* computationOf(const NodeState& state);

// Collective over my render cluster: the k-d tree over the cluster (a
// computation's cost is per node, so it always splits cells evenly), the
// run placed on it (moved from the bricks before, or started at step 0 on
// a new cluster), advanced to `step`, and this rank's brick of it.
Distribution distributeComputation(NodeState& state, int step);

// Collective over my render cluster: advances the run to `step` with the
// scene's parameters and returns this rank's brick of it. Every rank of the
// cluster throws pvr::Error when `step` lies before the run's.
core::Brick advanceComputation(NodeState& state, int step);

// The status entries of a computation volume (docs/runtime.md): its name,
// the step shown, the parameters in force and every declared one's range.
std::vector<proto::KeyValue> computationStatus(const NodeState& state, const ComputationSource& computation);

}  // namespace pvr::node
