// The cameras of RenderRotation (paper 003: "render rotate 0,1,0 15,59:60"):
// frame k turns the eye and the up vector of the scene's camera about its
// look_at point (for the automatic camera, the volume's centre), about
// `axis`, by 360 degrees * k / stepsPerTurn.
#pragma once

#include <cstdint>

#include "camera.h"
#include "pvr_protocol.h"

namespace pvr::node {

class Rotation {
 public:
  // Throws pvr::Error (kInvalidArgument) for a request that fails
  // proto::RenderRotation::check, the one rule (decoding already enforces
  // it on the wire; this guards requests built in-process).
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
