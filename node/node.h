// What every rank of a pvr-node server holds between actions: its place in
// the layout, the dataset brick, the resolved scene, the frames of the
// wave in flight. Actions (actions/*.cpp) read and change it; the master
// also holds the connection's sink for finished frames.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "brick.h"
#include "brick_cache.h"
#include "command_channel.h"
#include "communicator.h"
#include "decompose/kd_tree.h"
#include "distribute.h"
#include "image.h"
#include "io/volume_io.h"
#include "layout.h"
#include "liveness.h"
#include "pvr_protocol.h"
#include "raycast/raycaster.h"
#include "runtime_settings.h"
#include "scene_bricks.h"
#include "scene.h"
#include "strategy.h"
#include "sub_communicator.h"
#include "thread_pool.h"

namespace pvr::node {

class RankWatch;

// One frame of the wave in flight, as this rank sees it.
struct WaveFrame {
  std::uint32_t number = 0;  // position in the request
  core::CameraSpec camera;
  int timestep = 0;     // the time step it shows
  core::Image partial;  // render ranks: this rank's brick, cut to its band
  double rend = 0, comp = 0, comm = 0;  // this rank's seconds on the frame
};

// Compositing measured per cluster, for "performance comp".
struct CompositeLog {
  double seconds = 0;  // sum over frames of this rank's comp + comm
  int frames = 0;
  composite::CompositeStats last;  // the last frame's traffic
};

// Ping-pong and blending rates measured at session start (action calibrate).
struct Calibration {
  double latency = 0;        // seconds per message, one way
  double bandwidth = 0;      // bytes per second
  double blendRate = 0;      // pixels "over" per second
};

struct NodeState {
  NodeState(comm::Communicator& worldComm, comm::CommandChannel& commandChannel, std::string dataDirectory)
      : world(worldComm), commands(commandChannel), dataDir(std::move(dataDirectory)) {}

  comm::Communicator& world;
  comm::CommandChannel& commands;  // the master's commands to the slaves
  std::string dataDir;  // real path; datasets resolve inside it
  // Every world rank's host name, in rank order, gathered once at start
  // (hosts.h): status `hosts`, and the host in a rank's failure text.
  std::vector<std::string> hosts;
  bool running = true;
  // The server's watch (rank_watch.h) and what it watches of this rank;
  // null in batch mode and tests.
  comm::Liveness* liveness = nullptr;
  RankWatch* watch = nullptr;

  // Layout.
  Layout layout;
  int cluster = -1;  // my cluster index; -1 for a dedicated master
  std::unique_ptr<comm::SubCommunicator> clusterComm;
  const ClusterPlan* myCluster() const { return cluster < 0 ? nullptr : &layout.clusters[std::size_t(cluster)]; }
  bool renders() const { return myCluster() && myCluster()->role == proto::ClusterRole::kRender; }

  // Scene and data.
  RuntimeSettings settings;
  std::string volumeKey;  // what the source was opened from
  std::unique_ptr<core::VolumeSource> source;
  core::Scene scene;  // resolved for source's grid
  core::RenderOptions renderOptions;
  int ghost = 0;
  std::optional<core::KdTree> tree;  // over my cluster's ranks
  // A scene of several volumes, or of one hidden (needsSceneBricks,
  // scene_bricks.h): `source` is the first,
  // these the others with their keys, in the scene's order; each volume's
  // value range (the first's is valueRange too). Empty for one volume.
  std::vector<std::unique_ptr<core::VolumeSource>> moreSources;
  std::vector<std::string> moreKeys;
  std::vector<std::optional<std::array<double, 2>>> volumeRanges;
  bool several() const { return needsSceneBricks(scene); }
  bool sourcesForSceneBricks = false;  // the sources were opened for the SceneBricks path
  // Every volume's source, the scene's order.
  std::vector<const core::VolumeSource*> sources() const {
    std::vector<const core::VolumeSource*> all{source.get()};
    for (const auto& s : moreSources) all.push_back(s.get());
    return all;
  }
  // The brick of the step on screen (scene.volume.timestep, or the step
  // of the frame a time request renders), ready to render; null without data.
  std::shared_ptr<ReadyBrick> current;
  // Steps held and read ahead for this rank (brick_cache.h); dropped with the tree.
  BrickCache cache;
  // The classification in force (ReadyBrick::classifiedAs): counts up on
  // every change of what classifying depends on (data.h, classify).
  std::uint64_t classification = 1;
  // Cache ranks (cache_cluster.h): per render rank served, by (render
  // cluster, index in it), its steps and the step it shows.
  struct ServedRank {
    std::unique_ptr<BrickCache> cache;
    int shown = -1;
  };
  std::map<std::pair<int, int>, ServedRank> served;
  // Time not yet charged to a frame (FrameTiming): reading bricks,
  // preprocessing them (value range, macrocells, classification), and the
  // rest of a (re)distribution (decomposition, scatter).
  double pendingRead = 0;
  double pendingPreprocess = 0;
  double pendingDist = 0;
  int rebalances = 0;
  double imbalance = 0;  // max/mean content per rank at the last transfer-function change (master's cluster)
  // The data's finite values, min and max over every brick; set by every
  // (re)distribution (loadBricks), on every rank.
  std::optional<std::array<double, 2>> valueRange;
  // Its histogram, core::kHistogramBins bins over valueRange (data_summary.h),
  // counted over the first render cluster's bricks; empty without data, and
  // while histogramPending: a load counts nothing (a first frame does not
  // need the counts, and counting costs as much again as the rest of
  // preprocessing); the first Status the master answers counts them
  // (countHistogram).
  std::vector<std::uint64_t> histogram;
  bool histogramPending = false;

  // The wave in flight.
  std::vector<WaveFrame> wave;
  // Collector: finished bands of the wave, by (wave slot, band).
  std::map<std::pair<int, int>, core::Image> bands;

  Calibration calibration;
  CompositeLog compositeLog;
  std::unique_ptr<core::ThreadPool> pool = std::make_unique<core::ThreadPool>(1);
  int poolThreads = 1;
  // Resizes the pool to settings.threads when that changed.
  void matchPoolToSettings();

  // Tests: each step of `injectedFailures` throws once, on its world rank
  // (--fail-once STEP@RANK; the steps are "render" and "composite").
  std::vector<std::pair<std::string, int>> injectedFailures;
  void maybeFail(const std::string& step);

  // Master only: what the last action answered (memory, latency reports).
  nlohmann::json reply;
  // Master only: seconds the last command took to reach the other ranks.
  double commandSeconds = 0;
  // Master only: where the collector's finished frames go, and a float
  // copy for exact comparison when dumpDir is set.
  std::function<void(proto::ImageFrame&&, bool final)> sendFrame;
  std::string dumpDir;
};

}  // namespace pvr::node
