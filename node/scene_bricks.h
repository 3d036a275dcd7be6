// One rank's part of a scene of several volumes (docs/scene.md, "Several
// volumes"; docs/runtime.md).
//
// The ranks of a render cluster split the union of the volumes' domains
// with one k-d tree (core::unionGrid): each rank owns a world-space region
// and holds, of every volume, the nodes the ray caster reads for the parts
// of rays in that region (core::volumeBoxFor), read through the same
// readers and scatter as one volume's bricks (distribute.h). Compositing
// takes the tree as for one volume. A scene of one visible volume never
// comes here: it keeps its own decomposition, bit for bit.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "brick.h"
#include "communicator.h"
#include "data_summary.h"
#include "decompose/kd_tree.h"
#include "decompose/union_regions.h"
#include "io/volume_io.h"
#include "raycast/scene_renderer.h"
#include "scene.h"

namespace pvr::node {

// Whether a scene renders through SceneBricks: several volumes, or one
// that is hidden (the one-volume path shows its volume whatever it says).
bool needsSceneBricks(const core::Scene& scene);

struct SceneBricks {
  core::KdTree tree;  // over core::unionGrid(grids), one leaf per rank
  core::WorldRegion region;
  std::vector<core::GridGeometry> grids;         // volume i's grid
  std::vector<std::optional<core::Brick>> bricks;  // volume i's nodes around the region; none when far
  // Volume i's fine counts of its nodes in the region (core::nodesIn):
  // bricks overlap, these do not. Null where the brick holds none.
  std::vector<std::shared_ptr<const core::FineHistogram>> counted;
  std::unique_ptr<core::SceneRenderer> renderer;   // over the bricks (makeRenderer)
  bool readPartially = true;        // every volume was read box by box (else rank 0 scattered some)
  std::uint64_t rootReadBytes = 0;  // the most rank 0 held of one volume while scattering

  const core::Brick* brick(std::size_t i) const { return bricks[i] ? &*bricks[i] : nullptr; }
  std::uint64_t bytes() const;
  core::LoadTimes loadTimes() const;  // summed over the bricks
  // Builds the renderer over the bricks (macrocells over the pool).
  void makeRenderer(core::ThreadPool* pool);
};

// The step of volume `source` that shows the scene's `timestep`: that step
// where it has it, else its last (a single volume is every step).
int stepShown(const core::VolumeSource& source, int timestep);

// The scene's timestep against its volumes, each opened at step 0 of its
// spec: every volume shows it where it has it, so it must be a step of
// the longest series (checkTimestep's error for that one otherwise).
// sources[i] is scene volume i's.
void checkSceneTimestep(const core::Scene& scene, const std::vector<const core::VolumeSource*>& sources);

// Collective over `comm`: the union tree, this rank's region and its part
// of every volume for rays sampled at `step` (world length). sources[i] is
// volume i, already at the step it shows.
SceneBricks distributeScene(const std::vector<const core::VolumeSource*>& sources, double step,
                            comm::Communicator& comm);

// Collective over `comm`: each volume's DataSummary (summarizeData over
// SceneBricks::counted, so each node counts once, as a serial count of
// the whole volume). `bricks` may be null (a rank holding no data); every
// rank passes the same volume count.
std::vector<std::optional<DataSummary>> summarizeVolumes(comm::Communicator& comm, const SceneBricks* bricks,
                                                         std::size_t volumes, bool counts);

}  // namespace pvr::node
