// The master/slave loop of pvr-node --server, after OSPRay's MPI offload
// worker: the master broadcasts {action index, JSON arguments}; every rank
// (master included) runs the action, which does its own communication;
// then all ranks agree on the outcome, so a failure on any rank is known
// to all with the rank that raised it, and nobody waits on a rank that
// gave up. Slaves run nothing but what the master names, until "shutdown".
#pragma once

#include <optional>
#include <string_view>

#include "node.h"

namespace pvr::node {

// Collective, first thing after MPI starts: every rank compares the hash of
// its action table with the others'. Throws pvr::Error on every rank alike
// when they differ (a different pvr-node build on some host).
void checkActionTables(comm::Communicator& world);

// Master: runs `name` on every rank; returns the agreed failure, if any.
// `broadcastSeconds` receives the time spent sending the command.
std::optional<comm::Failure> invoke(NodeState& state, std::string_view name, const ActionArgs& args = {},
                                  double* broadcastSeconds = nullptr);

// Slaves: wait for commands (sleeping between polls, so an idle session
// costs no CPU) and run them until the master sends "shutdown".
void serveSlave(NodeState& state);

}  // namespace pvr::node
