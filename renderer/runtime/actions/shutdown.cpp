// shutdown: every rank leaves its loop; the job ends with MPI_Finalize.
#include "../node.h"

namespace pvr::runtime::actions {

void shutdown(NodeState& state, const ActionArgs&) { state.running = false; }

}  // namespace pvr::runtime::actions
