// comp_latency: per compositing cluster (render clusters that composite
// themselves, and composite clusters), the latency model's estimate beside
// the measured mean compositing time per frame, into state.reply.
//
// Model, calibrated by the calibrate action: a rank's compositing time is
// messages * latency + bytes / bandwidth + pixels / blend rate, over the
// traffic of its last frame (messages and encoded bytes it sent, or for a
// composite-cluster rank received, and pixels blended); the cluster takes
// as long as its slowest rank. Measured: the slowest rank's mean of
// compositing compute plus communication time per frame.
#include "table.h"

namespace pvr::node::actions {

void CompLatency::run(NodeState& state, const CompLatency& args) {
  const auto& log = state.compositeLog;
  const auto& cal = state.calibration;
  const double model = double(log.last.messagesSent + log.last.gatherMessagesSent) * cal.latency +
                       (cal.bandwidth > 0 ? double(log.last.encodedBytesSent + log.last.gatherBytesSent) / cal.bandwidth : 0) +
                       (cal.blendRate > 0 ? double(log.last.pixelsSent) / cal.blendRate : 0);
  const double mean = log.frames > 0 ? log.seconds / log.frames : 0.0;
  const std::size_t n = std::size_t(state.world.size());
  std::vector<double> values(n * 3, 0.0);
  values[std::size_t(state.world.rank()) * 3 + 0] = model;
  values[std::size_t(state.world.rank()) * 3 + 1] = mean;
  values[std::size_t(state.world.rank()) * 3 + 2] = double(log.frames);
  state.world.allReduceMax(values);  // each rank fills only its own slots
  if (state.world.rank() != 0) return;

  const int only = args.cluster;
  nlohmann::json clusters = nlohmann::json::array();
  for (std::size_t c = 0; c < state.layout.clusters.size(); ++c) {
    const ClusterPlan& plan = state.layout.clusters[c];
    const bool composites = plan.role == proto::ClusterRole::kComposite ||
                            (plan.role == proto::ClusterRole::kRender && plan.compositor < 0);
    if (!composites || (only >= 0 && std::size_t(only) != c)) continue;
    double modelMax = 0, measuredMax = 0, frames = 0;
    for (int r : plan.ranks) {
      modelMax = std::max(modelMax, values[std::size_t(r) * 3]);
      measuredMax = std::max(measuredMax, values[std::size_t(r) * 3 + 1]);
      frames = std::max(frames, values[std::size_t(r) * 3 + 2]);
    }
    nlohmann::json entry = {{"index", c}, {"role", roleName(plan.role)}, {"ranks", plan.ranks.size()},
                            {"model_seconds", modelMax}, {"frames_measured", int(frames)}};
    entry["measured_seconds"] = frames > 0 ? nlohmann::json(measuredMax) : nlohmann::json(nullptr);
    clusters.push_back(entry);
  }
  state.reply = {{"clusters", clusters},
                 {"calibration", {{"latency_seconds", cal.latency}, {"bandwidth_bytes_per_second", cal.bandwidth},
                                  {"blend_pixels_per_second", cal.blendRate}}}};
}

}  // namespace pvr::node::actions
