// load_dataset {"scene": document, "runtime": settings}: opens the scene's
// volume on every rank (headers only) and has each render cluster read it
// as bricks plus ghost layers, each rank its own box straight from the file
// (or its cluster's rank 0 scattering for formats that cannot read part of
// a file; distribute.h).
#include "../data.h"
#include "../node.h"

namespace pvr::node::actions {

void loadDataset(NodeState& state, const ActionArgs& args) {
  comm::runAgreed(state.world, [&] {
    const RuntimeSettings settings = settingsFrom(args.value("runtime", nlohmann::json::object()), state.settings);
    const RuntimeSettings old = state.settings;
    state.settings = settings;
    try {
      openScene(state, args.at("scene"));
    } catch (...) {
      state.settings = old;
      throw;
    }
    state.matchPoolToSettings();
  });
  distributeData(state);
}

}  // namespace pvr::node::actions
