// The compositing step of a wave (actions::Wave): the sub-images the render
// ranks hold become one band per render cluster at the collector (world
// rank 0).
//
//   - a render cluster without a composite cluster composites itself with
//     the session's strategy on its cluster communicator; its rank 0 sends
//     the band to the collector. In a coarse wave (an interactive render's
//     first pixels, coarse_frame.h) its ranks send their sub-images
//     straight to its rank 0 instead, which blends them in visibility
//     order: one message each, no strategy rounds, no agreement;
//   - a render cluster served by a composite cluster of m ranks: its rank 0
//     sends the frame's visibility order to the composite ranks; render
//     rank at position p of that order sends its sub-image to composite
//     rank floor(p*m/n) (contiguous runs of the order); each composite rank
//     blends its run front to back as the images arrive, then the
//     composite ranks reduce in a binary tree (rank j takes j + stride,
//     front over back, since runs are in order); their rank 0 sends the band;
//   - the collector receives every band of every frame of the wave, in
//     frame and band order, into state.bands.
//
// Every rank that someone waits for always sends: an image or the failure
// that stopped it. A rank whose render failed composites an empty image,
// so its cluster's strategy runs to the end on every rank, and the
// cluster's agreement after compositing carries the failure into the band.
#pragma once

#include <optional>

#include "node.h"

namespace pvr::node {

// Collective over the world. `failure` comes in as this rank's failure so
// far (its render) and goes out as the first failure this rank knows of:
// its own, its cluster's, or at the collector any band's. `coarse`: the
// wave is a coarse one.
void compositeWave(NodeState& state, bool coarse, std::optional<comm::Failure>& failure);

}  // namespace pvr::node
