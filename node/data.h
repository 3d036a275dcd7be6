// The dataset on the ranks: open, resolve the scene, give each rank of
// every render cluster its brick plus ghosts (distribute.h), classify, and
// rebalance a content-balanced decomposition when a new transfer function
// leaves it uneven. Functions marked collective run on every rank of the
// world (ranks outside render clusters return at once where they hold no data).
#pragma once

#include <string>

#include "node.h"

namespace pvr::node {

// What a new scene asks of the bricks.
enum class Reload {
  kNone,  // re-classify at most
  kStep,  // show another time step of the same volume (same tree)
  kAll,   // a new volume or new ghost layers: distribute again
};

// Local: parses the scene document `sceneJson` (validated by the master,
// dataset path resolved) and opens its volume if it differs from the one
// open (the volume's key leaves out the timestep: a new step re-reads
// bricks, not headers); checks the timestep against the dataset's steps;
// resolves the scene. Changes nothing when it throws.
Reload openScene(NodeState& state, const std::string& sceneJson);


// Collective over the world: render clusters read their bricks (dropping
// the old ones; distributeData), then every rank learns the data's value
// range. A rank whose cluster failed to read takes part in the exchange,
// then throws the cluster's failure.
void loadBricks(NodeState& state);

// Collective over each render cluster: its ranks read their bricks of the
// scene's timestep (a new tree; the brick cache starts over).
void distributeData(NodeState& state);

// Collective over the world: render clusters show the scene's timestep
// (showStep), then every rank learns its value range, as loadBricks.
void loadStep(NodeState& state);

// Collective over the world: the histogram of the data on screen when a
// load left it to be counted (NodeState::histogramPending), over the first
// render cluster's bricks; a no-op otherwise.
void countHistogram(NodeState& state);

// Who learns of a failure to show a step that each rank reads alone (from
// the cache or on demand; a distribution always agrees).
enum class StepFailure {
  kAgreed,  // every rank of the cluster throws the first failure
  // Only the rank that failed throws: a wave carries the failure to the
  // others with the sub-images it sends anyway (actions/wave.cpp), so a
  // rank that has its step renders at once instead of waiting for the
  // slowest read (8 ranks on 2 cores: the waiting ranks poll).
  kOwn,
};

// Collective over my render cluster (no-op elsewhere) unless `failures`
// is kOwn and the step is read per rank: makes `step` the brick on
// screen, from the cache, read on demand, or by a distribution when the
// format cannot read a box alone. Read and preprocessing time of a step
// not read ahead go to pendingRead / pendingPreprocess.
void showStep(NodeState& state, int step, StepFailure failures = StepFailure::kAgreed);

// Collective: render clusters with a content-balanced decomposition
// measure how even the new transfer function leaves their bricks and
// rebuild the tree when max/mean content passes the threshold.
void rebalanceIfNeeded(NodeState& state);

// Local: (re)builds the renderer's tables for the current scene. Every
// call starts a new classification (NodeState::classification): call it
// on every change of the transfer function or the render options.
void classify(NodeState& state);

// The classification in force, for the bricks the cache reads ahead
// (brick_cache.h, AheadClassifier): copies of the transfer function and
// render options, so the background thread never reads the state.
AheadClassifier aheadClassifier(const NodeState& state);

// Drops the dataset (after a layout change every cluster re-reads).
void dropData(NodeState& state);

}  // namespace pvr::node
