#include "rotation.h"

#include <cmath>
#include <numbers>

#include "error.h"

namespace pvr::node {

Rotation::Rotation(const core::CameraSpec& base, const proto::RenderRotation& r)
    : base_(base), start_(r.start), stepsPerTurn_(r.stepsPerTurn) {
  if (const auto refusal = r.check(proto::Limits{}))
    throw Error(ErrorCode::kInvalidArgument, "rotation: " + refusal->text);
  // check() guarantees this length is finite and nonzero.
  const double length = std::hypot(r.axis[0], r.axis[1], r.axis[2]);
  axis_ = {r.axis[0] / length, r.axis[1] / length, r.axis[2] / length};
  frames_ = int(r.frameCount());
}

core::CameraSpec Rotation::camera(int index) const {
  const double angle = 2 * std::numbers::pi * double(start_ + index) / double(stepsPerTurn_);
  core::CameraSpec c = base_;
  c.eye = base_.lookAt + core::rotateAbout(base_.eye - base_.lookAt, axis_, angle);
  c.up = core::rotateAbout(base_.up, axis_, angle);
  return c;
}

}  // namespace pvr::node
