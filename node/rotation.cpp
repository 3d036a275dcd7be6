#include "rotation.h"

#include <cmath>
#include <numbers>

#include "error.h"

namespace pvr::node {

namespace {

// v turned by `angle` radians about unit axis k (Rodrigues).
core::Vec3 turn(const core::Vec3& v, const core::Vec3& k, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return v * c + cross(k, v) * s + k * (dot(k, v) * (1 - c));
}

}  // namespace

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
  c.eye = base_.lookAt + turn(base_.eye - base_.lookAt, axis_, angle);
  c.up = turn(base_.up, axis_, angle);
  return c;
}

}  // namespace pvr::node
