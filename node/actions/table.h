// The action table: the one list of what the master may ask of every rank
// (action.h says what an action is, dispatch.h how it runs). Adding an
// action is its struct here plus its line in ActionTable, and one file
// actions/NAME.cpp defining its run. Every rank hashes the names in table
// order at start, so a rank built from another table refuses to run.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "../action.h"
#include "../runtime_settings.h"
#include "../wave_io.h"

namespace pvr::node::actions {

// Every rank leaves its loop (shutdown.cpp).
struct Shutdown {
  static constexpr std::string_view kName = "shutdown";
  static auto fields(auto&) { return std::tie(); }
  static void run(NodeState& state, const Shutdown& args);
};

// Arranges the ranks into clusters and groups; the clusters re-read the
// dataset (set_layout.cpp).
struct SetLayout {
  static constexpr std::string_view kName = "set_layout";
  std::vector<proto::ClusterSpec> clusters;  // empty: one render cluster of every rank
  static auto fields(auto& self) { return std::tie(self.clusters); }
  static void run(NodeState& state, const SetLayout& args);
};

// Latency, bandwidth and blend rate for the compositing model (calibrate.cpp).
struct Calibrate {
  static constexpr std::string_view kName = "calibrate";
  static auto fields(auto&) { return std::tie(); }
  static void run(NodeState& state, const Calibrate& args);
};

// A new scene and runtime settings, both validated by the master: opens the
// volume if it changed, re-reads, rebalances or re-classifies the bricks
// (set_scene.cpp).
struct SetScene {
  static constexpr std::string_view kName = "set_scene";
  std::string sceneJson;  // the whole scene document, dataset path resolved
  RuntimeSettings settings;
  static auto fields(auto& self) { return std::tie(self.sceneJson, self.settings); }
  static void run(NodeState& state, const SetScene& args);
};

// One wave of a request, one frame per group: render, composite, and the
// collector sends the frames in order (wave.cpp).
struct Wave {
  static constexpr std::string_view kName = "wave";
  std::uint32_t request = 0;     // the client's request id, for the dumped frames' names
  std::vector<FrameView> frames;  // frame g goes to group g
  std::uint32_t lastFrame = 0;   // the request's last frame number: sent as FINAL
  // The steps of the request's next frames, in order, after this wave's:
  // frame j of the list goes to group j % groups, whose render ranks read
  // it ahead (brick_cache.h).
  std::vector<std::int32_t> upcoming;
  // 1, or an interactive render's coarse wave: its frames are rendered at
  // 1/reduction of the pixels per axis and sent at that size (coarse_frame.h).
  std::int32_t reduction = 1;
  static auto fields(auto& self) {
    return std::tie(self.request, self.frames, self.lastFrame, self.upcoming, self.reduction);
  }
  static void run(NodeState& state, const Wave& args);
};

// Each render rank's brick cache: hits, misses, bytes held, read-ahead
// seconds, into state.reply (report_cache.cpp).
struct ReportCache {
  static constexpr std::string_view kName = "report_cache";
  std::int32_t cluster = -1;  // a cluster index, or -1 for all
  static auto fields(auto& self) { return std::tie(self.cluster); }
  static void run(NodeState& state, const ReportCache& args);
};

// The data's histogram, counted the first time a Status asks after a load
// (data.h countHistogram; count_histogram.cpp).
struct CountHistogram {
  static constexpr std::string_view kName = "count_histogram";
  static auto fields(auto&) { return std::tie(); }
  static void run(NodeState& state, const CountHistogram& args);
};

// Dataset bytes per rank and cluster, into state.reply (report_memory.cpp).
struct ReportMemory {
  static constexpr std::string_view kName = "report_memory";
  std::int32_t cluster = -1;  // a cluster index, or -1 for all
  static auto fields(auto& self) { return std::tie(self.cluster); }
  static void run(NodeState& state, const ReportMemory& args);
};

// The compositing latency model beside the measured time, into state.reply
// (comp_latency.cpp).
struct CompLatency {
  static constexpr std::string_view kName = "comp_latency";
  std::int32_t cluster = -1;  // a cluster index, or -1 for all
  static auto fields(auto& self) { return std::tie(self.cluster); }
  static void run(NodeState& state, const CompLatency& args);
};

}  // namespace pvr::node::actions

namespace pvr::node {

using ActionTable = ActionList<
    actions::Shutdown,
    actions::SetLayout,
    actions::Calibrate,
    actions::SetScene,
    actions::Wave,
    actions::ReportMemory,
    actions::CompLatency,
    actions::ReportCache,
    actions::CountHistogram>;

}  // namespace pvr::node
