// The master's answer to StatusRequest ("list status"): connection state,
// the hosts of the ranks, the layout, the settings and the lists a client offers (strategies from
// the composite registry, decompositions from distribute.h), and once a
// dataset is loaded the camera in use, image size, bounds, value range and
// resolved transfer function. Keys and formats: docs/runtime.md.
#pragma once

#include <cstdint>
#include <vector>

#include "node.h"

namespace pvr::node {

// What the master knows beside NodeState.
struct SessionStatus {
  bool rendering = false;
  std::uint32_t framesSent = 0;
  const RuntimeSettings& settings;  // the session's, whether a dataset is loaded or not
  bool cameraSet = false;           // the scene sets a camera (else it is the automatic one)
};

std::vector<proto::KeyValue> statusEntries(const NodeState& state, const SessionStatus& session);

}  // namespace pvr::node
