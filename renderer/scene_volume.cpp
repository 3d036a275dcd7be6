#include "scene_volume.h"

namespace pvr::core {

std::unique_ptr<VolumeSource> openSceneVolume(const VolumeSpec& spec) {
  if (!spec.file.empty()) return openVolumeFile(spec.file);
  if (spec.spacing) return openProcedural(spec.procedural, spec.dims, *spec.spacing);
  return openProcedural(spec.procedural, spec.dims);
}

}  // namespace pvr::core
