// The action table: the one list of what a master may ask of its slaves.
// Adding an action is one file in this directory plus its line here (the
// declaration sits beside it). Every rank hashes the names in this order at
// start (dispatch.h), so a rank built from another table refuses to run.
#include "../node.h"

namespace pvr::node {

namespace actions {
void shutdown(NodeState&, const ActionArgs&);
void setLayout(NodeState&, const ActionArgs&);
void calibrate(NodeState&, const ActionArgs&);
void loadDataset(NodeState&, const ActionArgs&);
void setScene(NodeState&, const ActionArgs&);
void render(NodeState&, const ActionArgs&);
void composite(NodeState&, const ActionArgs&);
void collect(NodeState&, const ActionArgs&);
void reportMemory(NodeState&, const ActionArgs&);
void compLatency(NodeState&, const ActionArgs&);
}  // namespace actions

const std::vector<ActionEntry>& actionTable() {
  static const std::vector<ActionEntry> table{
      {"shutdown", actions::shutdown},
      {"set_layout", actions::setLayout},
      {"calibrate", actions::calibrate},
      {"load_dataset", actions::loadDataset},
      {"set_scene", actions::setScene},
      {"render", actions::render},
      {"composite", actions::composite},
      {"collect", actions::collect},
      {"report_memory", actions::reportMemory},
      {"comp_latency", actions::compLatency},
  };
  return table;
}

}  // namespace pvr::node
