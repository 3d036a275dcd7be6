#include "computation_source.h"

#include "io/source_util.h"
#include "scene_volume.h"

namespace pvr::node {

core::Brick ComputationSource::readBox(const core::NodeBox& owned, const core::NodeBox& stored) const {
  const ComputationEntry& entry = run_.entry();
  core::checkReadBoxes(entry.name, grid(), owned, stored);
  const int shown = entry.shown(Parameters(entry, {}));
  core::Brick brick = core::Brick::forOverwrite(grid(), type(), owned, stored);
  std::vector<double> values(entry.fields.size());
  float* out = brick.as<float>();
  for (std::int64_t z = stored.lo.z; z <= stored.hi.z; ++z)
    for (std::int64_t y = stored.lo.y; y <= stored.hi.y; ++y)
      for (std::int64_t x = stored.lo.x; x <= stored.hi.x; ++x) {
        entry.initial(grid(), {x, y, z}, values);
        *out++ = float(values[std::size_t(shown)]);
      }
  brick.updateValueRange();
  return brick;
}

std::string ComputationSource::describe() const {
  return std::string(run_.entry().name) + ": " + core::shapeText(grid(), type()) + " (computation)";
}

std::unique_ptr<core::VolumeSource> openNodeVolume(const core::VolumeSpec& spec, const core::DataDirectory* within) {
  if (spec.computation.empty()) return core::openSceneVolume(spec, within);
  const ComputationEntry& entry = computationNamed(spec.computation);
  auto source = std::make_unique<ComputationSource>(entry, core::generatedGrid(spec.dims, spec.spacing, spec.computation));
  core::checkTimestep(spec, *source);
  return source;
}

ComputationSource* asComputation(core::VolumeSource* source) { return dynamic_cast<ComputationSource*>(source); }

const ComputationSource* asComputation(const core::VolumeSource* source) {
  return dynamic_cast<const ComputationSource*>(source);
}

}  // namespace pvr::node
