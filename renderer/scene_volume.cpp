#include "scene_volume.h"

#include "io/source_util.h"

namespace pvr::core {

std::unique_ptr<VolumeSource> openSceneVolume(const VolumeSpec& spec, const DataDirectory* within) {
  if (!spec.computation.empty())
    throw Error(ErrorCode::kInvalidArgument, "volume.computation '" + spec.computation +
                                                 "': a computation runs on the ranks of a pvr-node session "
                                                 "(docs/steering.md), not from a file or a generator");
  std::unique_ptr<VolumeSource> source;
  if (!spec.file.empty()) source = openVolumeFile(spec.file, within);
  else if (spec.spacing) source = openProcedural(spec.procedural, spec.dims, *spec.spacing);
  else source = openProcedural(spec.procedural, spec.dims);
  checkTimestep(spec, *source);
  return source;
}

void checkTimestep(const VolumeSpec& spec, const VolumeSource& source) {
  const int steps = source.steps();
  if (spec.timestep >= 0 && spec.timestep < steps) return;
  const std::string name = spec.file.empty() ? spec.procedural : fileNameOf(spec.file);
  const std::string has = steps == 1 ? "is a single volume (timestep 0 only)"
                                     : "has " + std::to_string(steps) + " time steps (0.." +
                                           std::to_string(steps - 1) + ")";
  throw Error(ErrorCode::kInvalidArgument, "timestep " + std::to_string(spec.timestep) + ": " + name + " " + has);
}

}  // namespace pvr::core
