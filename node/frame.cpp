#include "frame.h"

#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <fstream>
#include <sstream>

#include "camera.h"
#include "data_summary.h"
#include "raycast/raycaster.h"
#include "scene_bricks.h"
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

// --early-termination over the scene's sampling.early_termination.
void overrideEarlyTermination(core::Scene& scene, const FrameOptions& options) {
  if (!options.earlyTermination) return;
  if (!(*options.earlyTermination > 0 && *options.earlyTermination <= 1))
    throw Error(ErrorCode::kInvalidArgument, "early termination must be in (0, 1]");
  scene.sampling.earlyTermination = *options.earlyTermination;
}

}  // namespace

double processAgeSeconds() {
  // Field 22 of /proc/self/stat is the start time in clock ticks after boot,
  // and CLOCK_BOOTTIME counts from boot too. The command name (field 2) may
  // hold spaces, so the fields are counted after its closing parenthesis.
  std::ifstream in("/proc/self/stat");
  std::string stat((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t close = stat.rfind(')');
  timespec now{};
  if (close == std::string::npos || ::clock_gettime(CLOCK_BOOTTIME, &now) != 0) return 0;
  std::istringstream fields(stat.substr(close + 1));
  std::string field;
  for (int i = 3; i <= 22 && fields >> field; ++i) {
    if (i < 22) continue;
    const double started = std::stod(field) / double(::sysconf(_SC_CLK_TCK));
    return std::max(0.0, double(now.tv_sec) + now.tv_nsec * 1e-9 - started);
  }
  return 0;
}

std::uint64_t peakRssBytes() {
  rusage usage{};
  if (::getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return std::uint64_t(usage.ru_maxrss) * 1024;  // Linux counts kilobytes
}

namespace {

// prepareFrame for a scene of several volumes (scene_bricks.h): the same
// phases, every volume opened, read around this rank's region of their
// union and mixed by one SceneRenderer.
PreparedFrame prepareSeveral(const core::Scene& sceneIn, const FrameOptions& options, comm::Communicator& comm) {
  PreparedFrame prepared;
  FrameResult& result = prepared.frame;
  RankReport& report = prepared.report;
  report.start = processAgeSeconds();

  const auto distStart = std::chrono::steady_clock::now();
  std::vector<std::unique_ptr<core::VolumeSource>> sources;
  std::vector<const core::VolumeSource*> shown;
  core::RenderOptions renderOptions;
  runAgreed(comm, [&] {
    composite::makeStrategy(options.strategy, options.strategyParams);
    if (options.decomposition != Decomposition::kKd)
      throw Error(ErrorCode::kInvalidArgument, "decomposition '" + std::string(decompositionName(options.decomposition)) +
                                                   "': a scene of several volumes is split by kd over their union");
    result.scene = sceneIn;
    std::vector<core::GridGeometry> grids;
    // Each opened at its first step; the timestep is the scene's (stepShown).
    const int timestep = sceneIn.volumes.front().source.timestep;
    std::vector<const core::VolumeSource*> opened;
    for (const core::SceneVolume& v : sceneIn.volumes) {
      core::VolumeSpec first = v.source;
      first.timestep = 0;
      sources.push_back(options.openVolume ? options.openVolume(first) : core::openSceneVolume(first));
      opened.push_back(sources.back().get());
      shown.push_back(&sources.back()->step(stepShown(*sources.back(), timestep)));
      grids.push_back(sources.back()->grid());
    }
    checkSceneTimestep(sceneIn, opened);
    core::resolveDefaults(result.scene, grids);
    overrideEarlyTermination(result.scene, options);
    renderOptions = core::renderOptionsFor(result.scene);
    for (const auto& source : sources) {
      result.volume += (result.volume.empty() ? "" : " + ") + source->describe();
      result.volumeBytes += std::uint64_t(source->grid().allNodes().nodeCount()) * core::scalarSize(source->type());
    }
  });

  auto bricks = std::make_shared<SceneBricks>(distributeScene(shown, renderOptions.step, comm));
  prepared.bricks.tree = bricks->tree;
  result.readPartially = bricks->readPartially;
  result.rootReadBytes = bricks->rootReadBytes;
  report.brickBytes = bricks->bytes();
  const core::LoadTimes loaded = bricks->loadTimes();
  report.read = loaded.read;
  report.dist = std::max(0.0, secondsSince(distStart) - loaded.read - loaded.preprocess);

  // A transfer function left to the data takes its own volume's range.
  const auto summaries = summarizeVolumes(comm, bricks.get(), result.scene.volumes.size(), false);
  for (std::size_t i = 0; i < summaries.size(); ++i)
    if (summaries[i])
      core::resolveDataDefaults(result.scene.volumes[i].transfer, summaries[i]->range[0], summaries[i]->range[1]);

  runAgreed(comm, [&] {
    prepared.camera.emplace(result.scene.camera, result.scene.image.width, result.scene.image.height);
    core::ThreadPool pool(options.threads);
    const auto prepStart = std::chrono::steady_clock::now();
    bricks->makeRenderer(&pool);
    bricks->renderer->classify(result.scene.volumes, renderOptions, &pool);
    report.prep = loaded.preprocess + secondsSince(prepStart);
    const auto start = std::chrono::steady_clock::now();
    prepared.partial = bricks->renderer->render(*prepared.camera, renderOptions, pool);
    report.rend = secondsSince(start);
  });
  prepared.scene = std::move(bricks);
  return prepared;
}

}  // namespace

PreparedFrame prepareFrame(const core::Scene& sceneIn, const FrameOptions& options,
                           comm::Communicator& comm) {
  if (needsSceneBricks(sceneIn)) return prepareSeveral(sceneIn, options, comm);
  PreparedFrame prepared;
  FrameResult& result = prepared.frame;
  RankReport& report = prepared.report;

  report.start = processAgeSeconds();

  // Open the volume, resolve the scene, check the strategy's name.
  const auto distStart = std::chrono::steady_clock::now();
  std::unique_ptr<core::VolumeSource> source;
  core::RenderOptions renderOptions;
  runAgreed(comm, [&] {
    composite::makeStrategy(options.strategy, options.strategyParams);
    source = options.openVolume ? options.openVolume(sceneIn.volumes.front().source) : core::openSceneVolume(sceneIn.volumes.front().source);
    source->setFineCounts(false);  // a frame reports no histogram: the reader counts nothing
    result.scene = sceneIn;
    core::resolveDefaults(result.scene, source->grid());
    overrideEarlyTermination(result.scene, options);
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
  // The reader's seconds are inside the distribution's; dist keeps the rest.
  const core::LoadTimes& loaded = prepared.bricks.brick.loadTimes();
  report.read = loaded.read;
  report.dist = std::max(0.0, secondsSince(distStart) - loaded.read - loaded.preprocess);

  // A transfer function left to the data takes the whole volume's range.
  const std::optional<DataSummary> summary = summarizeData(comm, &prepared.bricks.brick, false);
  if (summary) core::resolveDataDefaults(result.scene.volumes.front().transfer, summary->range[0], summary->range[1]);

  // Preprocess (macrocell grid, classification) and render my brick into
  // its screen rectangle.
  runAgreed(comm, [&] {
    prepared.camera.emplace(result.scene.camera, result.scene.image.width, result.scene.image.height);
    core::ThreadPool pool(options.threads);
    const auto prepStart = std::chrono::steady_clock::now();
    core::BrickRenderer renderer(prepared.bricks.brick, &pool);
    renderer.classify(result.scene.volumes.front().transfer, renderOptions, &pool);
    report.prep = loaded.preprocess + secondsSince(prepStart);
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
  report.peakRssBytes = peakRssBytes();
  result.ranks = gatherReports(report, comm);
  if (comm.rank() == 0) result.image = std::move(composite.image);
  return result;
}

FrameResult renderFrame(const core::Scene& scene, const FrameOptions& options,
                        comm::Communicator& comm) {
  return compositeFrame(prepareFrame(scene, options, comm), options, comm);
}

}  // namespace pvr::node
