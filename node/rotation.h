// The cameras of RenderRotation (paper 003: "render rotate 0,1,0 15,59:60"):
// frame k turns the eye and the up vector of the scene's camera about its
// look_at point (for the automatic camera, the volume's centre), about
// `axis`, by 360 degrees * k / stepsPerTurn.
#pragma once

#include <cstdint>

#include "camera.h"
#include "pvr_protocol.h"

namespace pvr::node {

// The most frames one rotation may ask for.
constexpr std::int64_t kMaxRotationFrames = 100000;

class Rotation {
 public:
  // Throws pvr::Error (kInvalidArgument) for a request no rotation answers:
  // stepsPerTurn 0, end before start, more than kMaxRotationFrames frames,
  // a zero or non-finite axis. (protocol's RenderRotation::check will hold
  // this rule once it exists; this check then goes.)
  Rotation(const core::CameraSpec& base, const proto::RenderRotation& request);
  int frames() const { return frames_; }
  // Frame `index` of the request (0 .. frames() - 1).
  core::CameraSpec camera(int index) const;

 private:
  core::CameraSpec base_;
  core::Vec3 axis_;  // unit length
  std::int32_t start_;
  std::uint32_t stepsPerTurn_;
  int frames_;
};

}  // namespace pvr::node
