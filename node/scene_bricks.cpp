#include "scene_bricks.h"

#include <algorithm>

#include "distribute.h"
#include "preprocess.h"
#include "scene_volume.h"

namespace pvr::node {

bool needsSceneBricks(const core::Scene& scene) {
  return scene.volumes.size() > 1 || !scene.volumes.front().visible;
}

std::uint64_t SceneBricks::bytes() const {
  std::uint64_t sum = 0;
  for (const auto& b : bricks)
    if (b) sum += b->byteSize();
  return sum;
}

core::LoadTimes SceneBricks::loadTimes() const {
  core::LoadTimes sum;
  for (const auto& b : bricks)
    if (b) {
      sum.read += b->loadTimes().read;
      sum.preprocess += b->loadTimes().preprocess;
    }
  return sum;
}

void SceneBricks::makeRenderer(core::ThreadPool* pool) {
  std::vector<const core::Brick*> held;
  for (std::size_t i = 0; i < bricks.size(); ++i) held.push_back(brick(i));
  renderer = std::make_unique<core::SceneRenderer>(held, grids, region, pool);
}

int stepShown(const core::VolumeSource& source, int timestep) { return std::min(timestep, source.steps() - 1); }

void checkSceneTimestep(const core::Scene& scene, const std::vector<const core::VolumeSource*>& sources) {
  std::size_t longest = 0;
  for (std::size_t i = 1; i < sources.size(); ++i)
    if (sources[i]->steps() > sources[longest]->steps()) longest = i;
  core::checkTimestep(scene.volumes[longest].source, *sources[longest]);
}

SceneBricks distributeScene(const std::vector<const core::VolumeSource*>& sources, double step,
                            comm::Communicator& comm) {
  SceneBricks out;
  comm::runAgreed(comm, [&] {
    for (const core::VolumeSource* s : sources) out.grids.push_back(s->grid());
    out.tree = core::KdTree::build(core::unionGrid(out.grids), comm.size(), splitAxisRule(Decomposition::kKd));
    out.region = core::regionOf(out.tree, comm.rank());
  });
  // Each volume in turn, so rank 0 holds at most one whole volume while scattering.
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const core::VolumeSource& source = *sources[i];
    const core::GridGeometry& grid = out.grids[i];
    const std::optional<core::Brick> whole = readWholeOnRoot(source, comm);
    if (whole) out.rootReadBytes = std::max<std::uint64_t>(out.rootReadBytes, whole->byteSize());
    out.readPartially = out.readPartially && source.canReadPartially();
    const auto boxOf = [&](int rank) { return core::volumeBoxFor(grid, core::regionOf(out.tree, rank), step); };
    out.bricks.push_back(obtainBrick(source, boxOf, 0, whole, comm));
    // The histogram's counts: the region's own nodes, one more pass.
    std::shared_ptr<const core::FineHistogram> counted;
    const core::Brick* brick = out.brick(i);
    const core::NodeBox mine = core::nodesIn(grid, out.region);
    if (brick && !mine.empty())
      counted = core::preprocessVoxels(brick->type(), brick->owned(), brick->stored(), brick->bytes(), nullptr, &mine)
                    .histogram;
    out.counted.push_back(std::move(counted));
  }
  return out;
}

std::vector<std::optional<DataSummary>> summarizeVolumes(comm::Communicator& comm, const SceneBricks* bricks,
                                                         std::size_t volumes, bool counts) {
  std::vector<std::optional<DataSummary>> out;
  for (std::size_t i = 0; i < volumes; ++i) {
    const core::Brick* brick = bricks && i < bricks->bricks.size() ? bricks->brick(i) : nullptr;
    out.push_back(summarizeData(comm, brick, counts && brick ? bricks->counted[i].get() : nullptr));
  }
  return out;
}

}  // namespace pvr::node
