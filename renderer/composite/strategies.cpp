// The table of compositing strategies. A new strategy is one file defining
// its factory, plus one declaration and one row here.
#include "strategy.h"

namespace pvr::composite {

std::unique_ptr<Strategy> makeBinarySwap(const StrategyParams&);
std::unique_ptr<Strategy> makeDirectSend(const StrategyParams&);
std::unique_ptr<Strategy> makeTree(const StrategyParams&);
std::unique_ptr<Strategy> makeRadixK(const StrategyParams&);

const std::vector<StrategyEntry>& strategies() {
  static const std::vector<StrategyEntry> table = {
      {"binary-swap", "pairs across each k-d split swap halves; log2(n) messages per rank", makeBinarySwap},
      {"direct-send", "one tile per rank; every rank sends each tile its part in one round", makeDirectSend},
      {"tree", "naive binary tree: each right subtree sends its whole image up", makeTree},
      {"radix-k", "groups of k ranks direct-send inside the group; k = --radix", makeRadixK},
  };
  return table;
}

std::unique_ptr<Strategy> makeStrategy(std::string_view name, const StrategyParams& params) {
  std::string known;
  for (const StrategyEntry& e : strategies()) {
    if (e.name == name) return e.make(params);
    known += (known.empty() ? "" : ", ") + std::string(e.name);
  }
  throw Error(ErrorCode::kInvalidArgument,
              "unknown compositing strategy '" + std::string(name) + "' (known: " + known + ")");
}

}  // namespace pvr::composite
