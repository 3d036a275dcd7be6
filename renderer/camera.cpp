#include "camera.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "error.h"

namespace pvr::core {

Camera::Camera(const CameraSpec& spec, int width, int height)
    : spec_(spec), width_(width), height_(height) {
  if (width < 1 || height < 1 || width > kMaxImageSide || height > kMaxImageSide)
    throw Error(ErrorCode::kInvalidArgument, "camera: image of " + std::to_string(width) + " x " +
                                                 std::to_string(height) + " pixels: each side must be in 1.." +
                                                 std::to_string(kMaxImageSide));
  const Vec3 view = spec.lookAt - spec.eye;
  if (!(length(view) > 0))
    throw Error(ErrorCode::kInvalidArgument, "camera: eye and look_at coincide");
  forward_ = normalize(view);
  const Vec3 side = cross(forward_, spec.up);
  if (!(length(side) > 1e-9 * length(spec.up)))
    throw Error(ErrorCode::kInvalidArgument, "camera: up is parallel to the view direction");
  right_ = normalize(side);
  up_ = cross(right_, forward_);

  const double aspect = double(width) / double(height);
  if (spec.projection == Projection::kOrthographic) {
    if (!(spec.height > 0)) throw Error(ErrorCode::kInvalidArgument, "camera: height must be > 0");
    halfHeight_ = spec.height / 2;
  } else {
    if (!(spec.fovYDeg > 0 && spec.fovYDeg < 180))
      throw Error(ErrorCode::kInvalidArgument, "camera: fov_y_deg must be in (0, 180)");
    halfHeight_ = std::tan(spec.fovYDeg * std::numbers::pi / 360.0);
  }
  halfWidth_ = halfHeight_ * aspect;
}

Ray Camera::ray(int x, int y) const {
  // Pixel centre in normalised image coordinates, [-1, 1], +y up.
  const double sx = (2.0 * (x + 0.5) / width_ - 1.0) * halfWidth_;
  const double sy = (1.0 - 2.0 * (y + 0.5) / height_) * halfHeight_;
  if (spec_.projection == Projection::kOrthographic)
    return {spec_.eye + right_ * sx + up_ * sy, forward_};
  return {spec_.eye, normalize(forward_ + right_ * sx + up_ * sy)};
}

PixelRect Camera::project(Vec3 lo, Vec3 hi) const {
  const PixelRect frame{0, 0, width_, height_};
  double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
  for (int c = 0; c < 8; ++c) {
    const Vec3 p{(c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z};
    const Vec3 v = p - spec_.eye;
    double sx = dot(v, right_), sy = dot(v, up_);
    if (spec_.projection == Projection::kPerspective) {
      const double depth = dot(v, forward_);
      if (depth <= 1e-9 * (1 + length(v))) return frame;  // box reaches behind the eye
      sx /= depth;
      sy /= depth;
    }
    // Continuous pixel coordinates (pixel x covers [x, x+1)).
    const double px = (sx / halfWidth_ + 1.0) * 0.5 * width_;
    const double py = (1.0 - sy / halfHeight_) * 0.5 * height_;
    xmin = std::min(xmin, px), xmax = std::max(xmax, px);
    ymin = std::min(ymin, py), ymax = std::max(ymax, py);
  }
  // One pixel of margin absorbs rounding; rays outside the box cost nothing.
  auto clampInt = [](double v) { return int(std::clamp(v, -1e9, 1e9)); };
  const PixelRect r{clampInt(std::floor(xmin)) - 1, clampInt(std::floor(ymin)) - 1,
                    clampInt(std::ceil(xmax)) + 1, clampInt(std::ceil(ymax)) + 1};
  return r.intersect(frame);
}

}  // namespace pvr::core
