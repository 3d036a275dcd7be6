#include "frame.h"

#include <chrono>
#include <cstring>

#include "camera.h"
#include "raycast/raycaster.h"
#include "scene_volume.h"
#include "thread_pool.h"

namespace pvr::node {

using comm::runAgreed;

namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::vector<RankReport> gatherReports(const RankReport& mine, comm::Communicator& comm) {
  comm::Bytes bytes(sizeof mine);
  std::memcpy(bytes.data(), &mine, sizeof mine);
  std::vector<RankReport> all;
  for (const comm::Bytes& b : comm.allGather(bytes)) {
    RankReport r;
    if (b.size() != sizeof r) throw Error(ErrorCode::kInternal, "rank report of the wrong size");
    std::memcpy(&r, b.data(), sizeof r);
    all.push_back(r);
  }
  return all;
}

}  // namespace

PreparedFrame prepareFrame(const core::Scene& sceneIn, const FrameOptions& options,
                           comm::Communicator& comm) {
  PreparedFrame prepared;
  FrameResult& result = prepared.frame;
  RankReport& report = prepared.report;

  // Open the volume, resolve the scene, check the strategy's name.
  const auto distStart = std::chrono::steady_clock::now();
  std::unique_ptr<core::VolumeSource> source;
  core::RenderOptions renderOptions;
  runAgreed(comm, [&] {
    composite::makeStrategy(options.strategy, options.strategyParams);
    source = options.openVolume ? options.openVolume(sceneIn.volume) : core::openSceneVolume(sceneIn.volume);
    result.scene = sceneIn;
    core::resolveDefaults(result.scene, source->grid());
    if (options.earlyTermination) {
      if (!(*options.earlyTermination > 0 && *options.earlyTermination <= 1))
        throw Error(ErrorCode::kInvalidArgument, "early termination must be in (0, 1]");
      result.scene.sampling.earlyTermination = *options.earlyTermination;
    }
    renderOptions = core::renderOptionsFor(result.scene);
    result.ghostLayers = core::ghostLayers(source->grid(), renderOptions);
    result.volume = source->describe();
    result.volumeBytes = std::uint64_t(source->grid().allNodes().nodeCount()) * core::scalarSize(source->type());
  });

  // Each rank gets its brick.
  prepared.bricks = distributeBricks(*source, result.scene, options.decomposition, result.ghostLayers, comm);
  result.readPartially = prepared.bricks.readPartially;
  result.rootReadBytes = prepared.bricks.rootReadBytes;
  report.brickBytes = prepared.bricks.brick.byteSize();
  report.dist = secondsSince(distStart);

  // Render my brick into its screen rectangle.
  runAgreed(comm, [&] {
    prepared.camera.emplace(result.scene.camera, result.scene.image.width, result.scene.image.height);
    core::ThreadPool pool(options.threads);
    core::BrickRenderer renderer(prepared.bricks.brick);
    renderer.classify(result.scene.transfer, renderOptions);
    const auto start = std::chrono::steady_clock::now();
    prepared.partial = renderer.render(*prepared.camera, renderOptions, pool);
    report.rend = secondsSince(start);
  });
  return prepared;
}

FrameResult compositeFrame(const PreparedFrame& prepared, const FrameOptions& options,
                           comm::Communicator& comm) {
  FrameResult result = prepared.frame;
  RankReport report = prepared.report;
  // The strategy's preconditions hold on every rank by now.
  composite::CompositeResult composite;
  runAgreed(comm, [&] {
    const auto strategy = composite::makeStrategy(options.strategy, options.strategyParams);
    composite::CompositeOptions compositeOptions;
    compositeOptions.codec = options.codec;
    composite = strategy->composite(prepared.partial, prepared.bricks.tree, *prepared.camera, comm,
                                    compositeOptions);
  });
  report.composite = composite.stats;
  report.comp = composite.stats.computeSeconds;
  report.comm = composite.stats.communicationSeconds;
  report.send = composite.stats.gatherSeconds;
  result.ranks = gatherReports(report, comm);
  if (comm.rank() == 0) result.image = std::move(composite.image);
  return result;
}

FrameResult renderFrame(const core::Scene& scene, const FrameOptions& options,
                        comm::Communicator& comm) {
  return compositeFrame(prepareFrame(scene, options, comm), options, comm);
}

}  // namespace pvr::node
