// shutdown: every rank leaves its loop; the job ends with MPI_Finalize.
#include "table.h"

namespace pvr::node::actions {

void Shutdown::run(NodeState& state, const Shutdown&) { state.running = false; }

}  // namespace pvr::node::actions
