// The dataset on the ranks: open, resolve the scene, give each rank of
// every render cluster its brick plus ghosts (distribute.h), classify, and
// rebalance a content-balanced decomposition when a new transfer function
// leaves it uneven. Functions marked collective run on every rank of the
// world (ranks outside render clusters return at once where they hold no data).
#pragma once

#include <nlohmann/json.hpp>

#include "node.h"

namespace pvr::node {

// The "runtime" object of a SetScene document over `s` (docs/runtime.md);
// throws pvr::Error (kInvalidArgument) naming a bad key.
RuntimeSettings settingsFrom(const nlohmann::json& runtime, RuntimeSettings s);

// Local: parses `doc` (volume paths already resolved by the master) and
// opens its volume if it differs from the one open; resolves the scene.
// Returns true when the volume changed.
bool openScene(NodeState& state, const nlohmann::json& doc);

// Collective: render clusters read their bricks (dropping the old ones).
void distributeData(NodeState& state);

// Collective: render clusters with a content-balanced decomposition
// measure how even the new transfer function leaves their bricks and
// rebuild the tree when max/mean content passes the threshold.
void rebalanceIfNeeded(NodeState& state);

// Local: (re)builds the renderer's tables for the current scene.
void classify(NodeState& state);

// Drops the dataset (after a layout change every cluster re-reads).
void dropData(NodeState& state);

}  // namespace pvr::node
