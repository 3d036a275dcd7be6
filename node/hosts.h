// Where the ranks run: every world rank's host name, gathered once when a
// job starts, and failures told with the host of the rank that raised them
// ("rank 3 on h2: /data/x.raw: no such file"). On a cluster the host is
// what a user needs first: a data directory missing on one machine, a full
// disk, a node that went away.
#pragma once

#include <string>
#include <vector>

#include "communicator.h"

namespace pvr::node {

// This process's host name (gethostname). A name holds only letters,
// digits, '-', '.' and '_' (RFC 1123 plus the underscore some sites use);
// any other character becomes '_', so a list of names is a Tcl list.
std::string hostName();

// Collective over `world`: every rank's hostName(), in rank order.
std::vector<std::string> gatherHostNames(comm::Communicator& world);

// `hosts` as a Tcl list, in rank order: "h1 h1 h2 h2".
std::string hostList(const std::vector<std::string>& hosts);

// `hosts` with consecutive ranks on one host folded, for reports:
// "h1 (ranks 0-1), h2 (ranks 2-3)".
std::string hostRuns(const std::vector<std::string>& hosts);

// The text of a rank's failure with its host: "rank R on HOST: message";
// Failure::describe()'s "rank R: message" when `hosts` does not name R.
std::string describeOnHost(const comm::Failure& failure, const std::vector<std::string>& hosts);

}  // namespace pvr::node
