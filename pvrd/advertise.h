// The address the ranks use to reach this host: where a session handler
// listens for its master's connect-back (docs/pvrd.md, "--advertise").
#pragma once

#include <string>
#include <string_view>

#include "options.h"

namespace pvr::daemon {

// The first host an Open MPI hostfile names: the first word of its first
// line that is not blank or a comment, without a "user@" prefix; empty
// when there is none.
std::string firstHostfileHost(std::string_view hostfileText);

// --advertise when given; otherwise the local address of the route towards
// the first host of --hostfile; otherwise 127.0.0.1. Empty, with error
// text, when the hostfile cannot be read or its first host not reached.
std::string advertiseAddress(const DaemonOptions& options, std::string& error);

}  // namespace pvr::daemon
