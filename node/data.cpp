#include "data.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <nlohmann/json.hpp>
#include <numeric>

#include "decompose/content.h"
#include "scene_volume.h"
#include "transfer.h"

namespace pvr::node {

namespace {

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// What identifies a volume: equal keys, equal data.
std::string volumeKeyOf(const core::VolumeSpec& v) {
  nlohmann::json key = {{"file", v.file}, {"procedural", v.procedural}, {"dims", {v.dims.x, v.dims.y, v.dims.z}}};
  if (v.spacing) key["spacing"] = {v.spacing->x, v.spacing->y, v.spacing->z};
  return key.dump();
}

}  // namespace

bool openScene(NodeState& state, const std::string& sceneJson) {
  core::Scene scene = core::parseScene(nlohmann::json::parse(sceneJson), state.dataDir);
  const std::string key = volumeKeyOf(scene.volume);
  const bool changed = key != state.volumeKey || !state.source;
  std::unique_ptr<core::VolumeSource> source;
  const core::VolumeSource* grid = state.source.get();
  if (changed) {
    source = core::openSceneVolume(scene.volume);
    grid = source.get();
  }
  core::resolveDefaults(scene, grid->grid());
  const core::RenderOptions options = core::renderOptionsFor(scene);
  const int ghost = core::ghostLayers(grid->grid(), options);
  // Nothing has changed yet: commit.
  if (changed) {
    dropData(state);
    state.source = std::move(source);
    state.volumeKey = key;
  }
  state.scene = scene;
  state.renderOptions = options;
  const bool ghostChanged = ghost != state.ghost;
  state.ghost = ghost;
  return changed || (ghostChanged && state.brick.byteSize() > 0);
}

void dropData(NodeState& state) {
  state.renderer.reset();
  state.brick = core::Brick();
  state.tree.reset();
}

void loadBricks(NodeState& state) {
  std::optional<comm::Failure> failure;
  try {
    distributeData(state);
  } catch (...) {
    failure = comm::failureOf(std::current_exception(), state.world.rank());
  }
  // Max of (-min, max) over the ranks that hold a brick.
  constexpr double kNone = -std::numeric_limits<double>::infinity();
  std::vector<double> range{kNone, kNone};
  if (state.renderer) range = {-state.brick.valueRange().min, state.brick.valueRange().max};
  state.world.allReduceMax(range);
  state.valueRange.reset();
  if (range[1] > kNone) state.valueRange = std::array<double, 2>{-range[0], range[1]};
  if (failure) throw comm::FailureError(*failure);
}

void distributeData(NodeState& state) {
  if (!state.renders() || !state.source) return;
  const auto start = std::chrono::steady_clock::now();
  dropData(state);
  comm::SubCommunicator& cluster = *state.clusterComm;
  // A failure agreed on the cluster already names the world rank it came from.
  Distribution d = distributeBricks(*state.source, state.scene, state.settings.decomposition, state.ghost, cluster);
  state.tree = std::move(d.tree);
  state.brick = std::move(d.brick);
  state.renderer = std::make_unique<core::BrickRenderer>(state.brick);
  classify(state);
  state.pendingDist += secondsSince(start);
}

void classify(NodeState& state) {
  if (state.renderer) state.renderer->classify(state.scene.transfer, state.renderOptions);
}

void rebalanceIfNeeded(NodeState& state) {
  if (!state.renders() || !state.tree || state.settings.decomposition != Decomposition::kBalanced) return;
  const auto start = std::chrono::steady_clock::now();
  comm::SubCommunicator& cluster = *state.clusterComm;

  // What the new transfer function shows in each brick.
  core::ContentGrid content;
  std::uint64_t mine = 0;
  comm::runAgreed(cluster, [&] {
    const core::TransferTable table(state.scene.transfer, state.scene.sampling.step);
    content = core::countContent(state.brick, table);
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
  // new brick (or takes its share of a scatter).
  std::optional<core::KdTree> tree;
  comm::runAgreed(cluster, [&] {
    tree = core::KdTree::buildBalanced(state.source->grid(), cluster.size(), kSplitAxisRule, content);
  });
  if (state.source->canReadPartially()) {
    state.renderer.reset();
    state.brick = core::Brick();
    comm::runAgreed(cluster, [&] {
      const int r = cluster.rank();
      state.brick = state.source->readBox(tree->ownedBox(r), core::storedBox(*tree, r, state.ghost));
    });
    state.tree = std::move(tree);
  } else {
    distributeData(state);  // balanced from scratch, rank 0 of the cluster scattering
  }
  state.renderer = std::make_unique<core::BrickRenderer>(state.brick);
  classify(state);
  ++state.rebalances;
  state.pendingDist += secondsSince(start);
}

}  // namespace pvr::node
