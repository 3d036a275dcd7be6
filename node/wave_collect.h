// The collecting step of a wave (actions::Wave): every rank contributes its
// timings, and the collector (world rank 0) assembles the bands into
// frames, converts them to 8-bit sRGB over the background, compresses and
// sends them to the client in frame order.
#pragma once

#include <cstdint>
#include <optional>

#include "node.h"

namespace pvr::node {

// Collective over the world (but for a coarse wave). Each frame carries rend, comp and comm as the
// max over ranks and send as the collector measured it; the wave's first
// frame also carries dist: the command's broadcast plus the slowest rank's
// (re)distribution since the last frame. The collector sends nothing when
// it knows of a failure (`failure`, its own or a band's); a failure while
// sending goes into `failure` and stops it. Frames go out at
// state.scene.image's size: a coarse wave's reduced one (coarse_frame.h).
// `coarse`: the wave of an interactive render's first pixels, which wait
// for no collective of their own: no timings are gathered, the frame
// carries the collector's own rend, comp and comm, and read, preprocess
// and distribute stay pending for the next wave's frame.
void collectWave(NodeState& state, std::uint32_t request, std::uint32_t lastFrame, bool coarse,
                 std::optional<comm::Failure>& failure);

}  // namespace pvr::node
