// The camera of the rendering contract: rays through pixel centres, row 0 at
// the top, orthographic or perspective; and where a box lands on screen.
#pragma once

#include "grid.h"
#include "image.h"
#include "scene.h"
#include "vec.h"

namespace pvr::core {

struct Ray {
  Vec3 origin;     // on the eye plane (orthographic) or the eye (perspective)
  Vec3 direction;  // unit length; samples lie at origin + t * direction, t >= 0
};

class Camera {
 public:
  // Throws pvr::Error for a degenerate view (eye == look_at, up parallel to
  // it) and for an image side outside 1..kMaxImageSide (scene.h).
  Camera(const CameraSpec& spec, int width, int height);

  int width() const { return width_; }
  int height() const { return height_; }
  Projection projection() const { return spec_.projection; }
  const CameraSpec& spec() const { return spec_; }

  // The ray through the centre of pixel (x, y). Depends on nothing but the
  // camera and the pixel, so every brick casts the same ray for a pixel.
  Ray ray(int x, int y) const;

  // A conservative screen rectangle covering the projection of the world
  // box [lo, hi]; the whole frame when part of the box is behind the eye.
  PixelRect project(Vec3 lo, Vec3 hi) const;

  // Camera-space basis in world coordinates.
  Vec3 right() const { return right_; }
  Vec3 up() const { return up_; }
  Vec3 forward() const { return forward_; }
  // World-space direction of a camera-space vector (x right, y up, z towards the viewer).
  Vec3 toWorld(Vec3 cameraVector) const {
    return right_ * cameraVector.x + up_ * cameraVector.y - forward_ * cameraVector.z;
  }

 private:
  CameraSpec spec_;
  int width_, height_;
  Vec3 right_, up_, forward_;
  double halfWidth_, halfHeight_;  // image-plane half extents: world units (ortho) or tangents (persp)
};

}  // namespace pvr::core
