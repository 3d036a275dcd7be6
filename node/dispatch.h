// The master/slave loop of pvr-node --server, after OSPRay's MPI offload
// worker: the master posts a command {action index, argument bytes} on the
// command channel; every rank (master included) runs the action, which
// does its own communication; then all ranks agree on the outcome, once
// per command, so a failure on any rank is known to all with the rank that
// raised it, and nobody waits on a rank that gave up. Slaves run nothing
// but what the master names, until "shutdown".
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>

#include "actions/table.h"
#include "node.h"

namespace pvr::node {

// Collective, first thing after MPI starts: every rank compares the hash of
// its action table with the others'. Throws pvr::Error on every rank alike
// when they differ (a different pvr-node build on some host).
void checkActionTables(comm::Communicator& world);

// Master: posts the command, records in state.commandSeconds how long that
// took, runs `runHere` and agrees with the other ranks on the outcome.
std::optional<comm::Failure> postAndRun(NodeState& state, int index, std::span<const std::uint8_t> arguments,
                                        const std::function<void()>& runHere);

// Master: runs action A with `args` on every rank; returns the agreed
// failure, if any.
template <Action A>
std::optional<comm::Failure> invoke(NodeState& state, const A& args) {
  constexpr int index = ActionTable::indexOf<A>();
  static_assert(index >= 0, "the action is not in ActionTable (actions/table.h)");
  return postAndRun(state, index, encodeArguments(args), [&] { A::run(state, args); });
}

// Slaves: wait for commands (sleeping between polls, so an idle session
// costs no CPU) and run them until the master sends "shutdown".
void serveSlave(NodeState& state);

}  // namespace pvr::node
