// The master's rules for steering (docs/steering.md): which scene patches
// may be applied while a sequence renders, and the check of a computation
// volume and its "parameters" against the registry (computations/) before
// the ranks see them.
#pragma once

#include <optional>
#include <string>

#include "pvr_protocol.h"
#include "scene_patch.h"

namespace pvr::node {

// A SetScene that changes only "parameters": the master applies it between
// the frames of a sequence, so it takes effect from the next frame's steps.
bool isSteeringPatch(const proto::Message& m);

// The error that refuses `next` (the session's scene with `request`
// applied): a computation the ranks do not know, a parameter it does not
// declare or a value outside its range (naming the parameter and its
// range), or "parameters" sent for a volume that is not a computation.
std::optional<proto::ProtocolError> checkSteering(const proto::SetScene& request, const SessionScene& next,
                                                  const std::string& dataDir);

}  // namespace pvr::node
