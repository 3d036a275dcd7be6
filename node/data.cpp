#include "data.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <nlohmann/json.hpp>
#include <numeric>

#include "cache_cluster.h"
#include "computation_data.h"
#include "data_summary.h"
#include "decompose/content.h"
#include "io/data_directory.h"
#include "scene_bricks.h"
#include "scene_volume.h"
#include "transfer.h"

namespace pvr::node {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// What identifies a volume: equal keys, equal data. The timestep is not
// part of it: another step of the same dataset keeps the headers open.
std::string volumeKeyOf(const core::VolumeSpec& v) {
  nlohmann::json key = {{"file", v.file},
                        {"procedural", v.procedural},
                        {"computation", v.computation},
                        {"dims", {v.dims.x, v.dims.y, v.dims.z}}};
  if (v.spacing) key["spacing"] = {v.spacing->x, v.spacing->y, v.spacing->z};
  return key.dump();
}

// Reads this rank's brick of any step of the open volume, for the cache:
// the boxes of the current tree, captured, so it never touches the state.
BrickCache::Reader stepReader(const NodeState& state) {
  if (!state.source->canReadPartially()) return nullptr;  // a step needs rank 0's read and scatter
  const int rank = state.clusterComm->rank();
  return [source = state.source.get(), owned = state.tree->ownedBox(rank),
          stored = core::storedBox(*state.tree, rank, state.ghost)](int step) {
    return source->step(step).readBox(owned, stored);
  };
}

// Local: classifies the brick on screen for the scene, as the
// classification in force.
void classifyShown(NodeState& state) {
  if (state.current && state.current->scene)
    state.current->scene->renderer->classify(state.scene.volumes, state.renderOptions, state.pool.get());
  else if (state.current) state.current->renderer->classify(state.scene.volumes.front().transfer, state.renderOptions, state.pool.get());
  if (state.current) state.current->classifiedAs = state.classification;
}

// Announces this rank's brick of any step of the open volume (the boxes
// of the current tree, captured, as stepReader's).
BrickCache::Prefetcher stepPrefetcher(const NodeState& state) {
  if (!state.source->canReadPartially()) return nullptr;
  return [source = state.source.get(), stored = core::storedBox(*state.tree, state.clusterComm->rank(), state.ghost)](
             int step) {
    try {
      source->step(step).prefetchBox(stored);
    } catch (...) {
      // A hint: a step that does not exist fails when it is read.
    }
  };
}

// Puts `ready` on screen and classifies it unless it was read ahead under
// the classification in force; charges what it cost to the next frame
// when it was read for it (not read ahead).
void putOnScreen(NodeState& state, std::shared_ptr<ReadyBrick> ready, bool readNow) {
  state.current = std::move(ready);
  if (readNow) {
    state.pendingRead += state.current->readSeconds;
    state.pendingPreprocess += state.current->preprocessSeconds;
  }
  if (state.current->classifiedAs == state.classification) return;
  const auto start = Clock::now();
  classifyShown(state);
  state.pendingPreprocess += secondsSince(start);
}

// Collective over my render cluster: a new tree and this rank's brick of
// `step`; the cache starts over with it.
void distributeStep(NodeState& state, int step) {
  const auto start = Clock::now();
  const double charged = state.pendingRead + state.pendingPreprocess;
  dropData(state);
  comm::SubCommunicator& cluster = *state.clusterComm;
  // A failure agreed on the cluster already names the world rank it came from.
  Distribution d =
      computationOf(state)
          ? distributeComputation(state, step)
          : distributeBricks(state.source->step(step), state.scene, state.settings.decomposition, state.ghost, cluster);
  state.tree = std::move(d.tree);
  putOnScreen(state, makeReady(std::move(d.brick), step), true);
  state.cache.reset(stepReader(state), stepPrefetcher(state));
  state.cache.insert(state.current);
  // The rest of the distribution: decomposition, scatter, waiting.
  state.pendingDist += secondsSince(start) - (state.pendingRead + state.pendingPreprocess - charged);
}

// Collective over my render cluster: the union tree and this rank's part
// of every volume at the step each shows for `step` (scene_bricks.h);
// nothing is cached or read ahead.
void distributeSeveral(NodeState& state, int step) {
  const auto start = Clock::now();
  const double charged = state.pendingRead + state.pendingPreprocess;
  dropData(state);
  comm::SubCommunicator& cluster = *state.clusterComm;
  std::vector<const core::VolumeSource*> shown;
  for (const core::VolumeSource* s : state.sources()) shown.push_back(&s->step(stepShown(*s, step)));
  auto bricks = std::make_shared<SceneBricks>(distributeScene(shown, state.renderOptions.step, cluster));
  state.tree = bricks->tree;
  auto ready = std::make_shared<ReadyBrick>();
  ready->step = step;
  const auto built = Clock::now();
  comm::runAgreed(cluster, [&] { bricks->makeRenderer(state.pool.get()); });
  ready->readSeconds = bricks->loadTimes().read;
  ready->preprocessSeconds = bricks->loadTimes().preprocess + secondsSince(built);
  ready->scene = std::move(bricks);
  putOnScreen(state, std::move(ready), true);
  state.cache.reset(nullptr);
  state.pendingDist += secondsSince(start) - (state.pendingRead + state.pendingPreprocess - charged);
}

// Whether my brick counts towards the histogram: the bricks of one render
// cluster (the first) cover the volume once; other clusters hold it again.
bool countsForHistogram(const NodeState& state) {
  if (!state.renders()) return false;
  for (std::size_t c = 0; c < state.layout.clusters.size(); ++c)
    if (state.layout.clusters[c].role == proto::ClusterRole::kRender) return int(c) == state.cluster;
  return false;
}

// Local: a transfer function the scene left to the data (automatic, or a
// preset to stretch) takes the data's range, and the bricks are classified
// again, once the range is known.
void applyDataDefaults(NodeState& state) {
  if (state.several()) {
    bool resolved = false;
    for (std::size_t i = 0; i < state.volumeRanges.size(); ++i) {
      core::TransferFunctionSpec& tf = state.scene.volumes[i].transfer;
      if (!state.volumeRanges[i] || !(tf.automatic || tf.rescaleToData)) continue;
      core::resolveDataDefaults(tf, (*state.volumeRanges[i])[0], (*state.volumeRanges[i])[1]);
      resolved = true;
    }
    if (resolved) classify(state);
    return;
  }
  core::TransferFunctionSpec& tf = state.scene.volumes.front().transfer;
  if (!state.valueRange || !(tf.automatic || tf.rescaleToData)) return;
  core::resolveDataDefaults(tf, (*state.valueRange)[0], (*state.valueRange)[1]);
  classify(state);
}

// Collective over the world, after a phase that may have failed on this
// rank: every rank learns the data's value range and histogram (of the
// bricks on screen), then a rank that failed throws; else the data's
// defaults are applied.
void agreeOnValueRange(NodeState& state, const std::optional<comm::Failure>& failure) {
  std::optional<DataSummary> summary;
  if (state.several()) {
    // Each volume's range; the first's is the dataset's (status, histogram).
    const SceneBricks* bricks = state.current ? state.current->scene.get() : nullptr;
    const auto summaries = summarizeVolumes(state.world, bricks, state.scene.volumes.size(), countsForHistogram(state));
    state.volumeRanges.assign(summaries.size(), std::nullopt);
    for (std::size_t i = 0; i < summaries.size(); ++i)
      if (summaries[i]) state.volumeRanges[i] = summaries[i]->range;
    summary = summaries.front();
  } else {
    const core::Brick* brick = state.current ? &state.current->brick : nullptr;
    summary = summarizeData(state.world, brick, false);  // the range; the histogram when asked (countHistogram)
  }
  state.valueRange.reset();
  state.histogram.clear();
  state.histogramPending = false;
  if (summary) {
    state.valueRange = summary->range;
    if (state.several()) state.histogram = summary->histogram;
    else state.histogramPending = true;
  }
  if (failure) throw comm::FailureError(*failure);
  applyDataDefaults(state);
}

}  // namespace

void countHistogram(NodeState& state) {
  if (!state.histogramPending) return;
  core::Brick* brick = state.current ? &state.current->brick : nullptr;
  const bool counts = countsForHistogram(state);
  std::optional<comm::Failure> failure;
  try {
    if (brick && counts) brick->countFineHistogram(state.pool.get());
  } catch (...) {
    failure = comm::failureOf(std::current_exception(), state.world.rank());
  }
  // Every rank takes part in the sums, then a rank that failed throws.
  const auto summary = summarizeData(state.world, brick, counts && !failure);
  state.histogram = summary ? summary->histogram : std::vector<std::uint64_t>{};
  state.histogramPending = false;
  if (failure) throw comm::FailureError(*failure);
}

namespace {

void collectFailure(NodeState& state, const std::function<void()>& phase) {
  std::optional<comm::Failure> failure;
  try {
    phase();
  } catch (...) {
    failure = comm::failureOf(std::current_exception(), state.world.rank());
  }
  agreeOnValueRange(state, failure);
}

// The one rule for a step number (core::checkTimestep), for a step the
// session shows other than the scene's own (render time).
void checkStep(const NodeState& state, int step) {
  if (state.several()) {
    core::Scene at = state.scene;
    for (core::SceneVolume& v : at.volumes) v.source.timestep = step;
    checkSceneTimestep(at, state.sources());
    return;
  }
  core::VolumeSpec spec = state.scene.volumes.front().source;
  spec.timestep = step;
  core::checkTimestep(spec, *state.source);
}

// openScene for a scene of several volumes: each volume opened unless the
// same one is open at its place in the list; any change of the volumes,
// the timestep or the step length reads every brick again (margins
// depend on the step; scene_bricks.h).
Reload openSeveral(NodeState& state, core::Scene scene) {
  if (state.settings.decomposition != Decomposition::kKd)
    throw Error(ErrorCode::kInvalidArgument,
                "decomposition '" + std::string(decompositionName(state.settings.decomposition)) +
                    "': a scene of several volumes is split by kd over their union");
  const std::size_t n = scene.volumes.size();
  const core::DataDirectory within(state.dataDir);
  std::vector<std::string> keys(n);
  std::vector<std::unique_ptr<core::VolumeSource>> opened(n);
  std::vector<const core::VolumeSource*> sources(n);
  bool changed = !state.source || !state.sourcesForSceneBricks || state.moreSources.size() + 1 != n;
  for (std::size_t i = 0; i < n; ++i) {
    keys[i] = volumeKeyOf(scene.volumes[i].source);
    const bool same = i == 0 ? state.source && keys[0] == state.volumeKey
                             : i - 1 < state.moreKeys.size() && state.moreKeys[i - 1] == keys[i];
    if (same) {
      sources[i] = i == 0 ? state.source.get() : state.moreSources[i - 1].get();
      continue;
    }
    // Opened at its first step: the scene's timestep is checked over all.
    core::VolumeSpec first = scene.volumes[i].source;
    first.timestep = 0;
    opened[i] = core::openSceneVolume(first, &within);
    sources[i] = opened[i].get();
    changed = true;
  }
  checkSceneTimestep(scene, sources);
  std::vector<core::GridGeometry> grids;
  for (const core::VolumeSource* s : sources) grids.push_back(s->grid());
  core::resolveDefaults(scene, grids);
  const core::RenderOptions options = core::renderOptionsFor(scene);
  // Nothing has changed yet: commit.
  if (changed) {
    dropData(state);
    std::unique_ptr<core::VolumeSource> first = opened[0] ? std::move(opened[0]) : std::move(state.source);
    std::vector<std::unique_ptr<core::VolumeSource>> more;
    for (std::size_t i = 1; i < n; ++i)
      more.push_back(opened[i] ? std::move(opened[i]) : std::move(state.moreSources[i - 1]));
    state.source = std::move(first);
    state.moreSources = std::move(more);
    state.volumeKey = keys[0];
    state.moreKeys.assign(keys.begin() + 1, keys.end());
    state.volumeRanges.assign(n, std::nullopt);
    state.sourcesForSceneBricks = true;
  }
  const bool stepChanged = scene.volumes.front().source.timestep != state.scene.volumes.front().source.timestep;
  const bool lengthChanged = options.step != state.renderOptions.step;
  state.scene = std::move(scene);
  state.renderOptions = options;
  state.ghost = core::ghostLayers(grids.front(), options);
  // The same volumes: their ranges are known, so are transfer functions
  // left to them (the caller classifies).
  for (std::size_t i = 0; i < n && i < state.volumeRanges.size(); ++i)
    if (state.volumeRanges[i])
      core::resolveDataDefaults(state.scene.volumes[i].transfer, (*state.volumeRanges[i])[0],
                                (*state.volumeRanges[i])[1]);
  return changed || stepChanged || lengthChanged ? Reload::kAll : Reload::kNone;
}

}  // namespace

Reload openScene(NodeState& state, const std::string& sceneJson) {
  core::Scene scene = core::parseScene(nlohmann::json::parse(sceneJson), state.dataDir);
  if (needsSceneBricks(scene)) return openSeveral(state, std::move(scene));
  const std::string key = volumeKeyOf(scene.volumes.front().source);
  // After several volumes, one reads its bricks again even if it was the first.
  const bool changed = key != state.volumeKey || !state.source || state.sourcesForSceneBricks;
  std::unique_ptr<core::VolumeSource> source;
  const core::VolumeSource* grid = state.source.get();
  if (changed) {
    // Only what lies inside the data directory: the client named it.
    const core::DataDirectory within(state.dataDir);
    source = openNodeVolume(scene.volumes.front().source, &within);
    source->setFineCounts(false);  // counted when first asked for (countHistogram)
    grid = source.get();
  }
  core::checkTimestep(scene.volumes.front().source, *grid);
  core::resolveDefaults(scene, grid->grid());
  const core::RenderOptions options = core::renderOptionsFor(scene);
  const int ghost = core::ghostLayers(grid->grid(), options);
  // Nothing has changed yet: commit.
  if (changed) {
    dropData(state);
    state.source = std::move(source);
    state.volumeKey = key;
    state.moreSources.clear();
    state.moreKeys.clear();
    state.volumeRanges.clear();
    state.sourcesForSceneBricks = false;
  }
  const bool stepChanged = scene.volumes.front().source.timestep != state.scene.volumes.front().source.timestep;
  state.scene = scene;
  state.renderOptions = options;
  // The same volume: its range is known, so is a transfer function left to
  // it (the caller classifies); a new volume's waits for loadBricks.
  core::TransferFunctionSpec& tf = state.scene.volumes.front().transfer;
  if (!changed && state.valueRange) core::resolveDataDefaults(tf, (*state.valueRange)[0], (*state.valueRange)[1]);
  const bool ghostChanged = ghost != state.ghost;
  state.ghost = ghost;
  // Every rank decides alike (a rank outside the render clusters holds no
  // brick, yet takes part in loadBricks' world agreement).
  if (changed || ghostChanged) return Reload::kAll;
  return stepChanged ? Reload::kStep : Reload::kNone;
}

void dropData(NodeState& state) {
  state.served.clear();  // first: their readers refer to the source
  state.cache.clear();
  state.current.reset();
  state.tree.reset();
}

void loadBricks(NodeState& state) {
  collectFailure(state, [&] { distributeData(state); });
}

void loadStep(NodeState& state) {
  collectFailure(state, [&] {
    const int step = state.scene.volumes.front().source.timestep;
    showStep(state, step);
    if (const ClusterPlan* me = state.myCluster(); me && me->role == proto::ClusterRole::kCache)
      for (int c : me->serves) serveStep(state, c, step, {});
  });
}

void distributeData(NodeState& state) {
  prepareCacheRank(state);
  if (!state.renders() || !state.source) return;
  if (state.several()) distributeSeveral(state, state.scene.volumes.front().source.timestep);
  else distributeStep(state, state.scene.volumes.front().source.timestep);
}

void showStep(NodeState& state, int step, StepFailure failures) {
  if (!state.renders() || !state.source) return;
  if (state.current && state.current->step == step) return;
  if (computationOf(state) && state.tree) {  // computed, not read: computation_data.h
    putOnScreen(state, makeReady(advanceComputation(state, step), step), true);
    return;
  }
  comm::SubCommunicator& cluster = *state.clusterComm;
  if (state.several()) {
    comm::runAgreed(cluster, [&] { checkStep(state, step); });
    distributeSeveral(state, step);
    return;
  }
  if (!state.tree || !state.source->canReadPartially()) {
    comm::runAgreed(cluster, [&] { checkStep(state, step); });
    distributeStep(state, step);  // keeps the decomposition's kind, not its tree
    return;
  }
  if (servedByCacheCluster(state, *state.myCluster())) {
    putOnScreen(state, receiveStep(state, step), true);
    return;
  }
  std::shared_ptr<ReadyBrick> ready;
  std::uint64_t misses = 0;
  auto take = [&] {
    checkStep(state, step);
    state.maybeFail("step");
    misses = state.cache.stats().misses;
    ready = state.cache.take(step);
  };
  if (failures == StepFailure::kOwn) take();
  else comm::runAgreed(cluster, take);
  putOnScreen(state, std::move(ready), state.cache.stats().misses > misses);
}

void classify(NodeState& state) {
  ++state.classification;  // bricks read ahead under the last one classify again when shown
  classifyShown(state);
}

AheadClassifier aheadClassifier(const NodeState& state) {
  if (state.several()) return {};  // nothing is read ahead
  return {state.classification, [transfer = state.scene.volumes.front().transfer,
                                  options = state.renderOptions](core::BrickRenderer& renderer) {
            renderer.classify(transfer, options, nullptr);
          }};
}

void rebalanceIfNeeded(NodeState& state) {
  if (!state.renders() || !state.tree || state.settings.decomposition != Decomposition::kBalanced || state.several())
    return;
  const auto start = Clock::now();
  comm::SubCommunicator& cluster = *state.clusterComm;

  // What the new transfer function shows in each brick.
  core::ContentGrid content;
  std::uint64_t mine = 0;
  comm::runAgreed(cluster, [&] {
    const core::TransferTable table(state.scene.volumes.front().transfer, state.scene.sampling.step);
    content = core::countContent(state.current->brick, table, {8, 8, 8}, state.pool.get());
    mine = core::totalContent(content);
  });
  cluster.allReduceSum(content.counts);
  std::vector<std::uint64_t> perRank(std::size_t(cluster.size()), 0);
  perRank[std::size_t(cluster.rank())] = mine;
  cluster.allReduceSum(perRank);
  const double total = double(std::accumulate(perRank.begin(), perRank.end(), std::uint64_t(0)));
  const double mean = total / double(cluster.size());
  const double worst = double(*std::max_element(perRank.begin(), perRank.end()));
  state.imbalance = mean > 0 ? worst / mean : 0;
  if (!(mean > 0) || worst / mean <= state.settings.rebalanceThreshold) return;

  // Every rank of the cluster builds the same balanced tree and reads its
  // new brick of the step on screen (or takes its share of a scatter).
  std::optional<core::KdTree> tree;
  comm::runAgreed(cluster, [&] {
    tree = core::KdTree::buildBalanced(state.source->grid(), cluster.size(), splitAxisRule(state.settings.decomposition), content);
  });
  const int step = state.current->step;
  if (state.source->canReadPartially()) {
    const double charged = state.pendingRead + state.pendingPreprocess;
    dropData(state);
    std::shared_ptr<ReadyBrick> ready;
    comm::runAgreed(cluster, [&] {
      const int r = cluster.rank();
      ready = makeReady(state.source->step(step).readBox(tree->ownedBox(r), core::storedBox(*tree, r, state.ghost)),
                        step);
    });
    state.tree = std::move(tree);
    putOnScreen(state, std::move(ready), true);
    state.cache.reset(stepReader(state), stepPrefetcher(state));
    state.cache.insert(state.current);
    state.pendingDist += secondsSince(start) - (state.pendingRead + state.pendingPreprocess - charged);
  } else {
    state.pendingDist += secondsSince(start);
    distributeStep(state, step);  // balanced from scratch, rank 0 of the cluster scattering
  }
  ++state.rebalances;
}

}  // namespace pvr::node
