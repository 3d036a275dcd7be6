// The node's errors as the protocol's Error message: pvr::Error codes map
// to wire codes, a rank's failure keeps its "rank R: ..." text.
#pragma once

#include "communicator.h"
#include "error.h"
#include "pvr_protocol.h"

namespace pvr::node {

proto::ProtocolError wireError(const pvr::Error& error);
proto::ProtocolError wireError(const comm::Failure& failure);

}  // namespace pvr::node
