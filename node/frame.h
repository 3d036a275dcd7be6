// One distributed frame: distribute bricks, render each rank's brick,
// composite with a registered strategy. The body of `pvr-node --batch`,
// and of the MPI tests and benchmarks, which call it inside one job.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camera.h"
#include "communicator.h"
#include "distribute.h"
#include "image.h"
#include "image_codec.h"
#include "io/volume_io.h"
#include "scene.h"
#include "strategy.h"

namespace pvr::node {

using VolumeOpener = std::function<std::unique_ptr<core::VolumeSource>(const core::VolumeSpec&)>;

struct FrameOptions {
  std::string strategy{composite::kDefaultStrategy};
  composite::StrategyParams strategyParams;
  Decomposition decomposition = Decomposition::kKd;
  std::optional<double> earlyTermination;  // overrides the scene's sampling.early_termination
  int threads = 1;                         // render threads per rank
  core::ImageCodec codec = core::ImageCodec::kAuto;
  // Opens the scene's volume (openSceneVolume when empty); tests wrap it to
  // make one rank's reads fail.
  VolumeOpener openVolume;
};

// One rank's account of a frame: the columns of Table 1 of the paper, with
// the distribution split into its phases so that a first frame's time adds
// up. On a rank the phases follow one another in this order.
struct RankReport {
  double start = 0;  // process start (exec by mpirun) to the frame's start: MPI init, host names, scene
  double read = 0;   // reading this rank's voxels (the reader's I/O seconds, Brick::loadTimes)
  double prep = 0;   // preprocessing: the reader's (value range, macrocell bounds while reading)
                     // plus building the renderer's macrocell grid and classifying
  double dist = 0;   // the rest of distribution: open, decompose, scatter
  double rend = 0;   // ray casting the brick
  double comp = 0;   // compositing computation
  double comm = 0;   // compositing communication
  double send = 0;   // gathering the tiles at rank 0
  composite::CompositeStats composite;
  std::uint64_t brickBytes = 0;    // voxel bytes this rank holds (owned + ghosts)
  std::uint64_t peakRssBytes = 0;  // the process's peak resident memory at the end of the frame
};

struct FrameResult {
  core::Image image;               // rank 0: the frame; elsewhere empty
  core::Scene scene;               // as resolved for the volume
  std::vector<RankReport> ranks;   // every rank's report, on every rank
  std::string volume;              // the source's description
  std::uint64_t volumeBytes = 0;   // the whole volume's voxel bytes
  int ghostLayers = 0;
  bool readPartially = false;
  std::uint64_t rootReadBytes = 0;  // whole volume held by rank 0 when scattering
};

// Collective. Throws pvr::Error on every rank alike if any rank fails
// (message "rank R: ..." of the lowest failing rank).
FrameResult renderFrame(const core::Scene& scene, const FrameOptions& options,
                        comm::Communicator& comm);

// Seconds since this process started (0 where /proc cannot tell), and its
// peak resident memory so far (getrusage): the report's start and RSS.
double processAgeSeconds();
std::uint64_t peakRssBytes();

// renderFrame in its two halves, for benchmarks that composite one
// rendering many ways: prepareFrame opens, distributes and renders (dist,
// rend); compositeFrame composites with options.strategy and options.codec.
struct SceneBricks;
struct PreparedFrame {
  FrameResult frame;      // scene, volume facts; no image or reports yet
  Distribution bricks;    // several volumes: only the tree (their union's)
  std::shared_ptr<SceneBricks> scene;  // several volumes: this rank's part of each (scene_bricks.h)
  core::Image partial;    // this rank's rendered brick
  std::optional<core::Camera> camera;
  RankReport report;      // start, read, prep, dist, rend, brickBytes
};
PreparedFrame prepareFrame(const core::Scene& scene, const FrameOptions& options,
                           comm::Communicator& comm);
FrameResult compositeFrame(const PreparedFrame& prepared, const FrameOptions& options,
                           comm::Communicator& comm);

}  // namespace pvr::node
