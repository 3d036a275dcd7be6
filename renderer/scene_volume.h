// The volume a scene names, opened from a file or generated.
#pragma once

#include <memory>

#include "io/volume_io.h"
#include "scene.h"

namespace pvr::core {

std::unique_ptr<VolumeSource> openSceneVolume(const VolumeSpec& spec);

}  // namespace pvr::core
