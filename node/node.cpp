#include "node.h"

namespace pvr::node {

void NodeState::matchPoolToSettings() {
  if (poolThreads == settings.threads) return;
  pool = std::make_unique<core::ThreadPool>(settings.threads);
  poolThreads = settings.threads;
}

void NodeState::maybeFail(const std::string& step) {
  for (auto it = injectedFailures.begin(); it != injectedFailures.end(); ++it) {
    if (it->first == step && it->second == world.rank()) {
      injectedFailures.erase(it);
      throw Error(ErrorCode::kIo, "injected failure in " + step);
    }
  }
}

}  // namespace pvr::node
