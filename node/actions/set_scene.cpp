// set_scene: a new scene document and runtime settings (docs/runtime.md),
// validated by the master already. Every rank parses the document once and
// opens the volume if it changed (headers only); the render clusters read
// their bricks again when the volume, the ghost layers or the decomposition
// changed, else re-classify them and rebalance a content-balanced
// decomposition that the new transfer function leaves uneven (data.h).
#include "../data.h"
#include "table.h"

namespace pvr::node::actions {

void SetScene::run(NodeState& state, const SetScene& args) {
  bool redistribute = false;
  comm::runAgreed(state.world, [&] {
    const RuntimeSettings old = state.settings;
    state.settings = args.settings;
    try {
      redistribute = openScene(state, args.sceneJson) || state.settings.decomposition != old.decomposition;
    } catch (...) {
      state.settings = old;
      throw;
    }
    state.matchPoolToSettings();
    classify(state);
  });
  if (redistribute) loadBricks(state);
  else rebalanceIfNeeded(state);
}

}  // namespace pvr::node::actions
