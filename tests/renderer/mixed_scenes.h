// Scenes of several volumes for the renderer's tests: smooth fields on
// boxes of any spacing and origin, two transfer functions that tell the
// volumes apart, and the scene entries that name them
// (raycast_mixed_test.cpp, raycast_mixed_bricks_test.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "raycast/scene_renderer.h"
#include "reference.h"
#include "scene.h"

namespace pvr::core::test {

// A volume of the scene: grid, voxels and transfer function.
struct TestVolume {
  Brick brick;
  TransferFunctionSpec tf;
  bool visible = true;
};

inline GridGeometry boxGrid(IVec3 dims, double spacing, Vec3 origin) {
  GridGeometry g;
  g.dims = dims;
  g.spacing = {spacing, spacing, spacing};
  g.origin = origin;
  return g;
}

// A smooth field over the grid's box (normalised coordinates): one broad
// Gaussian off-centre plus a gentle wave; values in [0, 1] (0..255 as uint8).
inline Brick smoothVolume(const GridGeometry& grid, Vec3 centre, ScalarType type = ScalarType::kFloat32) {
  const Vec3 lo = grid.domainMin(), hi = grid.domainMax();
  return makeVolume(grid, type, [=](Vec3 p) {
    Vec3 q;
    for (int a = 0; a < 3; ++a) q[a] = (p[a] - lo[a]) / (hi[a] - lo[a]);
    const Vec3 d = q - centre;
    const double v = 0.75 * std::exp(-dot(d, d) / 0.08) + 0.15 * (1 + std::sin(5 * q.x + 3 * q.y - 2 * q.z));
    const double scaled = std::min(1.0, v);
    return type == ScalarType::kUInt8 ? 255 * scaled : scaled;
  });
}

inline TransferFunctionSpec tfOf(std::vector<TransferPoint> points, double unitDistance) {
  TransferFunctionSpec tf;
  tf.points = std::move(points);
  tf.unitDistance = unitDistance;
  return tf;
}

// Warm and cool media, opacities up to 0.3 per unit distance.
inline TransferFunctionSpec warm(double unit) {
  return tfOf({{0.0, 0.2, 0.0, 0.0, 0.0}, {0.3, 0.9, 0.4, 0.1, 0.05}, {1.0, 1.0, 0.9, 0.6, 0.3}}, unit);
}
inline TransferFunctionSpec cool(double unit) {
  return tfOf({{0.0, 0.0, 0.1, 0.3, 0.0}, {0.4, 0.1, 0.5, 0.9, 0.08}, {1.0, 0.6, 1.0, 0.9, 0.25}}, unit);
}

// The scene's entries for `volumes`: named v0, v1, ..., their transfer
// functions and visibility.
inline std::vector<SceneVolume> sceneVolumes(const std::vector<TestVolume>& volumes) {
  std::vector<SceneVolume> out(volumes.size());
  for (std::size_t i = 0; i < volumes.size(); ++i) {
    out[i].name = "v" + std::to_string(i);
    out[i].transfer = volumes[i].tf;
    out[i].visible = volumes[i].visible;
  }
  return out;
}

// The scenes the reference and the bricks are tested on. Two volumes that
// overlap partly, spacings 1 and 0.7, around (14, 12, 10):
inline std::vector<TestVolume> overlappingVolumes() {
  std::vector<TestVolume> volumes;
  volumes.push_back({smoothVolume(boxGrid({24, 22, 20}, 1.0, {0, 0, 0}), {0.4, 0.45, 0.5}), warm(1.0)});
  volumes.push_back({smoothVolume(boxGrid({22, 22, 22}, 0.7, {9.3, 6.1, 4.7}), {0.6, 0.5, 0.4}), cool(0.7)});
  return volumes;
}
// A small fine volume (spacing 0.5) wholly inside a coarse one, around 13.5:
inline std::vector<TestVolume> nestedVolumes() {
  std::vector<TestVolume> volumes;
  volumes.push_back({smoothVolume(boxGrid({28, 28, 28}, 1.0, {0, 0, 0}), {0.3, 0.5, 0.5}), warm(1.0)});
  volumes.push_back({smoothVolume(boxGrid({21, 19, 17}, 0.5, {9.1, 8.7, 10.3}), {0.5, 0.5, 0.5}), cool(0.5)});
  return volumes;
}
// Two disjoint volumes side by side along x, a gap between them:
inline std::vector<TestVolume> disjointVolumes() {
  std::vector<TestVolume> volumes;
  volumes.push_back({smoothVolume(boxGrid({16, 16, 16}, 1.0, {0, 0, 0}), {0.5, 0.5, 0.5}), warm(1.0)});
  volumes.push_back({smoothVolume(boxGrid({20, 20, 20}, 0.8, {20.5, 0.3, -0.4}), {0.5, 0.4, 0.6}), cool(0.8)});
  return volumes;
}

// The whole scene in one SceneRenderer, as a full frame.
inline Image castScene(const std::vector<TestVolume>& volumes, const Camera& camera, const RenderOptions& o,
                       RenderStats* stats = nullptr) {
  std::vector<const Brick*> bricks;
  for (const TestVolume& v : volumes) bricks.push_back(&v.brick);
  SceneRenderer renderer(bricks);
  renderer.classify(sceneVolumes(volumes), o);
  return renderer.render(camera, o, pool(), stats).toFullFrame();
}

inline double maxAlpha(const Image& image) {
  double a = 0;
  for (const Rgba& p : image.pixels()) a = std::max(a, double(p.a));
  return a;
}

inline Camera orthographic(Vec3 eye, Vec3 at, double height) {
  return makeCamera(Projection::kOrthographic, eye, at, {0, 0, 1}, height, 40, 40);
}
inline Camera perspective(Vec3 eye, Vec3 at, double fovYDeg) {
  return makeCamera(Projection::kPerspective, eye, at, {0, 0, 1}, fovYDeg, 40, 40);
}

}  // namespace pvr::core::test
