// One rank's part of a running computation (computation.h): its fields over
// its owned nodes plus ghost layers, the step count, and the collectives
// that keep the ranks of a render cluster in step: the ghost-layer exchange
// before each step, moving the fields when the cluster's bricks change, and
// the brick the renderer draws.
//
// Every function marked collective is called by every rank of `comm` (a
// render cluster), in the same order, with the same arguments but `comm`.
#pragma once

#include <vector>

#include "brick.h"
#include "communicator.h"
#include "computation.h"

namespace pvr::node {

// The tag of the messages a computation's ranks exchange: ghost layers and
// fields moving to new bricks (beside wave_io.h's tags).
constexpr int kComputationTag = 25010;

class ComputationRun {
 public:
  ComputationRun(const ComputationEntry& entry, const core::GridGeometry& grid) : entry_(entry), grid_(grid) {}

  const ComputationEntry& entry() const { return entry_; }
  const core::GridGeometry& grid() const { return grid_; }
  int steps() const { return steps_; }  // steps taken since the initial condition

  // Collective: this rank takes the nodes of owned[comm.rank()] (`owned`
  // lists every rank's box, in rank order; together they cover the grid)
  // and keeps `ghost` layers around them (at least the computation's halo).
  // `members` names comm's ranks (their world ranks, in order). The first
  // time, or on other members than before (a new layout), the fields start
  // from the initial condition at step 0; otherwise they move from the
  // ranks that held them, step count kept.
  void place(comm::Communicator& comm, const std::vector<int>& members, const std::vector<core::NodeBox>& owned,
             int ghost);
  // Collective: one step with `parameters`.
  void step(comm::Communicator& comm, const Parameters& parameters);
  // Collective: the field the parameters show, as float32 on `stored`
  // (which must lie within the owned box grown by the ghost of place()),
  // rendering this rank's owned box. Its value range is computed.
  core::Brick brick(comm::Communicator& comm, const Parameters& parameters, const core::NodeBox& stored);
  // Local: every field of this rank's block (owned nodes and ghost layers),
  // for tests comparing runs.
  const FieldBlock& fields() const { return now_; }
  const core::NodeBox& owned() const { return owned_[std::size_t(rank_)]; }

 private:
  // The block box of `owned` with `layers` ghost layers, clipped to the grid.
  core::NodeBox grownInGrid(const core::NodeBox& owned, int layers) const;
  // Collective: fills the `layers` ghost layers of now_ from their owners.
  void exchangeGhosts(comm::Communicator& comm, int layers);

  const ComputationEntry& entry_;
  core::GridGeometry grid_;
  std::vector<int> members_;          // the world ranks of the cluster placed on
  std::vector<core::NodeBox> owned_;  // every rank's, once placed
  int rank_ = 0;
  int ghost_ = 0;
  FieldBlock now_, next_;
  int steps_ = 0;
};

}  // namespace pvr::node
