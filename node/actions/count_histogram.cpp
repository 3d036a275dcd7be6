// count_histogram: the histogram a load left to be counted (data.h).
#include "../data.h"
#include "table.h"

namespace pvr::node::actions {

void CountHistogram::run(NodeState& state, const CountHistogram&) { countHistogram(state); }

}  // namespace pvr::node::actions
