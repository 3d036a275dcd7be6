#include "computation_data.h"

namespace pvr::node {

namespace {

// Collective over my render cluster: steps the run up to `step` and
// returns its brick for my stored box.
core::Brick stepTo(NodeState& state, ComputationSource& computation, const core::KdTree& tree, int step) {
  ComputationRun& run = computation.run();
  comm::SubCommunicator& cluster = *state.clusterComm;
  std::optional<Parameters> parameters;
  comm::runAgreed(cluster, [&] {
    if (step < run.steps())
      throw Error(ErrorCode::kInvalidArgument, "step " + std::to_string(step) + ": " + computation.describe() +
                                                   " is at step " + std::to_string(run.steps()) +
                                                   " and cannot go back");
    parameters.emplace(run.entry(), state.scene.parameters);
  });
  while (run.steps() < step) {
    run.step(cluster, *parameters);
    if (state.liveness) ++state.liveness->progress;  // a long advance is not a hang
  }
  return run.brick(cluster, *parameters, core::storedBox(tree, cluster.rank(), state.ghost));
}

}  // namespace

ComputationSource* computationOf(const NodeState& state) { return asComputation(state.source.get()); }

Distribution distributeComputation(NodeState& state, int step) {
  ComputationSource& computation = *computationOf(state);
  comm::SubCommunicator& cluster = *state.clusterComm;
  Distribution d;
  std::vector<core::NodeBox> owned;
  comm::runAgreed(cluster, [&] {
    // The "kd" decomposition's tree: equal nodes per rank, axes alternating.
    core::KdTree tree = core::KdTree::build(computation.grid(), cluster.size(), splitAxisRule(Decomposition::kKd));
    for (int r = 0; r < cluster.size(); ++r) owned.push_back(tree.ownedBox(r));
    d.tree = std::move(tree);
  });
  computation.run().place(cluster, state.myCluster()->ranks, owned, state.ghost);
  d.brick = stepTo(state, computation, d.tree, step);
  d.readPartially = true;  // nothing was read, nothing scattered
  return d;
}

core::Brick advanceComputation(NodeState& state, int step) { return stepTo(state, *computationOf(state), *state.tree, step); }

std::vector<proto::KeyValue> computationStatus(const NodeState& state, const ComputationSource& computation) {
  const ComputationEntry& entry = computation.run().entry();
  std::string values, ranges;
  // The scene's parameters were checked when it was set: the values in force.
  const Parameters inForce(entry, state.scene.parameters);
  for (const ParameterSpec& p : entry.parameters) {
    values += (values.empty() ? "" : " ") + std::string(p.name) + " " + parameterText(inForce[p.name]);
    ranges += (ranges.empty() ? "{" : " {") + std::string(p.name) + " " + parameterText(p.initial) + " " + parameterText(p.min) +
              " " + parameterText(p.max) + " {" + std::string(p.help) + "}}";
  }
  return {{"computation", std::string(entry.name)},
          {"computation_summary", std::string(entry.summary)},
          {"step", std::to_string(state.scene.volumes.front().source.timestep)},
          {"parameters", values},
          {"parameter_ranges", ranges}};
}

}  // namespace pvr::node
