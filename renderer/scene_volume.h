// The volume a scene names, opened from a file or generated, and the check
// that the scene's timestep is one of its steps.
#pragma once

#include <memory>

#include "io/volume_io.h"
#include "scene.h"

namespace pvr::core {

// Opens the volume and checks spec.timestep against it (checkTimestep).
// A computation volume is not opened here: it runs on the ranks (node/computations/).
// Throws pvr::Error naming the file or procedural volume.
// With `within` (a server opening what a client named) the volume's files
// must lie inside that directory (io/data_directory.h).
std::unique_ptr<VolumeSource> openSceneVolume(const VolumeSpec& spec, const DataDirectory* within = nullptr);

// Throws pvr::Error(kInvalidArgument) unless 0 <= spec.timestep <
// source.steps(): "timestep 7: run.series.json has 5 time steps (0..4)".
// A caller that keeps the source open and changes only the timestep calls
// this itself.
void checkTimestep(const VolumeSpec& spec, const VolumeSource& source);

}  // namespace pvr::core
