// shutdown: every rank leaves its loop; the job ends with MPI_Finalize.
#include "../node.h"

namespace pvr::node::actions {

void shutdown(NodeState& state, const ActionArgs&) { state.running = false; }

}  // namespace pvr::node::actions
