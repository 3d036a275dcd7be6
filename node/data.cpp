#include "data.h"

#include <algorithm>
#include <chrono>
#include <numeric>

#include "decompose/content.h"
#include "scene_volume.h"
#include "transfer.h"

namespace pvr::node {

namespace {

constexpr core::SplitAxisRule kAxisRule = core::SplitAxisRule::kAlternating;

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

std::string volumeKeyOf(const core::VolumeSpec& v) {
  if (!v.file.empty()) return "file:" + v.file;
  std::string key = "procedural:" + v.procedural;
  for (int a = 0; a < 3; ++a) key += ":" + std::to_string(v.dims[a]);
  for (int a = 0; a < 3; ++a) key += ":" + std::to_string(v.spacing ? (*v.spacing)[a] : 0.0);
  return key;
}

}  // namespace

RuntimeSettings settingsFrom(const nlohmann::json& j, RuntimeSettings s) {
  if (!j.is_object()) throw Error(ErrorCode::kInvalidArgument, "runtime: must be an object");
  for (const auto& [key, value] : j.items()) {
    if (key == "strategy") {
      s.strategy = value.get<std::string>();
    } else if (key == "decomposition") {
      const auto d = value.get<std::string>();
      if (d == "kd") s.decomposition = Decomposition::kKd;
      else if (d == "balanced") s.decomposition = Decomposition::kBalanced;
      else throw Error(ErrorCode::kInvalidArgument, "runtime.decomposition: kd or balanced, not '" + d + "'");
    } else if (key == "rebalance_threshold") {
      s.rebalanceThreshold = value.get<double>();
      if (!(s.rebalanceThreshold >= 1)) throw Error(ErrorCode::kInvalidArgument, "runtime.rebalance_threshold: >= 1");
    } else if (key == "pixels") {
      const auto p = value.get<std::string>();
      if (p == "rgb8") s.format = proto::PixelFormat::kRgb8;
      else if (p == "rgba8") s.format = proto::PixelFormat::kRgba8;
      else throw Error(ErrorCode::kInvalidArgument, "runtime.pixels: rgb8 or rgba8, not '" + p + "'");
    } else if (key == "compression") {
      const auto c = value.get<std::string>();
      if (c == "none") s.compression = proto::Compression::kNone;
      else if (c == "rle") s.compression = proto::Compression::kRle;
      else if (c == "zlib") s.compression = proto::Compression::kZlib;
      else throw Error(ErrorCode::kInvalidArgument, "runtime.compression: none, rle or zlib, not '" + c + "'");
    } else if (key == "threads") {
      s.threads = value.get<int>();
      if (s.threads < 1 || s.threads > 256) throw Error(ErrorCode::kInvalidArgument, "runtime.threads: 1..256");
    } else {
      throw Error(ErrorCode::kInvalidArgument, "runtime." + key + ": unknown key");
    }
  }
  return s;
}

bool openScene(NodeState& state, const nlohmann::json& doc) {
  core::Scene scene = core::parseScene(doc, state.dataDir);
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
  composite::makeStrategy(state.settings.strategy);  // a bad name fails here, on every rank
  // Nothing has changed yet: commit.
  if (changed) {
    dropData(state);
    state.source = std::move(source);
    state.volumeKey = key;
  }
  state.sceneDoc = doc;
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
  const int me = state.world.rank();

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
    tree = core::KdTree::buildBalanced(state.source->grid(), cluster.size(), kAxisRule, content);
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
