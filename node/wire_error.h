// The node's errors as the protocol's Error message: pvr::Error codes map
// to wire codes, a rank's failure is told with its rank and that rank's
// host, "rank R on HOST: ..." (hosts.h).
#pragma once

#include <string>
#include <vector>

#include "communicator.h"
#include "error.h"
#include "pvr_protocol.h"

namespace pvr::node {

proto::ProtocolError wireError(const pvr::Error& error);
// `hosts`: every world rank's host name (NodeState::hosts).
proto::ProtocolError wireError(const comm::Failure& failure, const std::vector<std::string>& hosts);

}  // namespace pvr::node
