// set_scene: a new scene document and runtime settings (docs/runtime.md),
// validated by the master already. Every rank parses the document once and
// opens the volume if it changed (headers only); the render clusters read
// their bricks again when the volume, the ghost layers or the decomposition
// changed, show another step of it when the timestep changed (from the
// brick cache when it holds it), else re-classify them and rebalance a content-balanced
// decomposition that the new transfer function leaves uneven (data.h).
#include "../data.h"
#include "table.h"

namespace pvr::node::actions {

void SetScene::run(NodeState& state, const SetScene& args) {
  // Reading a volume may take minutes: the longer stall limit applies.
  const comm::LivenessScope loading(state.liveness, comm::LivenessScope::Kind::kLoading);
  Reload reload = Reload::kNone;
  comm::runAgreed(state.world, [&] {
    const RuntimeSettings old = state.settings;
    state.settings = args.settings;
    try {
      reload = openScene(state, args.sceneJson);
      if (state.settings.decomposition != old.decomposition) reload = Reload::kAll;
    } catch (...) {
      state.settings = old;
      throw;
    }
    state.matchPoolToSettings();
    state.cache.setBudget(cacheBudgetBytes(state.settings));
    for (auto& [key, served] : state.served) served.cache->setBudget(cacheBudgetBytes(state.settings) / state.served.size());
    // Bricks about to be read again are classified once they are (loadBricks):
    // classified now, with options asking for more ghost layers than they
    // hold (a quality target's step levels), they would fail.
    if (reload != Reload::kAll) classify(state);
  });
  if (reload == Reload::kAll) loadBricks(state);
  else if (reload == Reload::kStep) loadStep(state);
  else rebalanceIfNeeded(state);
}

}  // namespace pvr::node::actions
