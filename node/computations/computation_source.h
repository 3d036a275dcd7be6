// A computation volume as the node opens it: a VolumeSource with the
// computation's grid (the scene's dims and spacing, placed as a procedural
// volume's) that holds this rank's run of it (computation_run.h). It has
// nothing to read: canReadPartially() is false, readBox gives the field
// the computation starts from, and the bricks on screen come from the run
// (computation_data.h). Its steps are the simulation's, unbounded.
#pragma once

#include <memory>

#include "computation_run.h"
#include "io/volume_io.h"
#include "scene.h"

namespace pvr::node {

class ComputationSource final : public core::VolumeSource {
 public:
  ComputationSource(const ComputationEntry& entry, const core::GridGeometry& grid) : run_(entry, grid) {}

  const core::GridGeometry& grid() const override { return run_.grid(); }
  core::ScalarType type() const override { return core::ScalarType::kFloat32; }
  bool canReadPartially() const override { return false; }
  // The shown field at step 0 with the default parameters.
  core::Brick readBox(const core::NodeBox& owned, const core::NodeBox& stored) const override;
  std::string describe() const override;
  // Any step a session asks for: the simulation computes it.
  int steps() const override { return kSteps; }

  ComputationRun& run() { return run_; }
  const ComputationRun& run() const { return run_; }

  static constexpr int kSteps = 0x7fffffff;

 private:
  ComputationRun run_;
};

// The volume `spec` names, opened as core::openSceneVolume does, except that
// a computation volume (spec.computation) becomes a ComputationSource on
// the grid of spec.dims and spec.spacing. Throws pvr::Error naming an
// unknown computation and the known ones.
std::unique_ptr<core::VolumeSource> openNodeVolume(const core::VolumeSpec& spec, const core::DataDirectory* within);

// The source as a computation, or null for a file or procedural volume.
ComputationSource* asComputation(core::VolumeSource* source);
const ComputationSource* asComputation(const core::VolumeSource* source);

}  // namespace pvr::node
