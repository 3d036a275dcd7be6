// set_scene {"scene": document, "runtime": settings}: new transfer function,
// camera, image size, sampling or runtime settings (docs/runtime.md). Opens
// and distributes the volume if it changed (as load_dataset), re-reads
// bricks when the ghost layers or the decomposition change, and rebalances
// a content-balanced decomposition that the new transfer function leaves
// uneven (data.h).
#include "../data.h"
#include "../node.h"

namespace pvr::node::actions {

void setScene(NodeState& state, const ActionArgs& args) {
  bool redistribute = false;
  comm::runAgreed(state.world, [&] {
    const RuntimeSettings old = state.settings;
    state.settings = settingsFrom(args.value("runtime", nlohmann::json::object()), old);
    try {
      redistribute = openScene(state, args.at("scene")) || state.settings.decomposition != old.decomposition;
    } catch (...) {
      state.settings = old;
      throw;
    }
    state.matchPoolToSettings();
    classify(state);
  });
  if (redistribute) distributeData(state);
  else rebalanceIfNeeded(state);
}

}  // namespace pvr::node::actions
