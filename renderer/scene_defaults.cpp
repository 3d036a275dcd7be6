// The values a scene leaves to the volume: unit distance, step and the
// automatic camera (docs/scene.md, "Defaults that need the volume").
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "error.h"
#include "scene.h"
#include "scene_json.h"

namespace pvr::core {

using scene_json::numberText;

namespace {

// Refuses a step that needs more than kMaxSamplesPerRay samples across
// `diagonal` (named by `across` in the message).
void checkSamplesPerRay(double step, double diagonal, const std::string& across) {
  if (diagonal / step <= kMaxSamplesPerRay) return;
  throw Error(ErrorCode::kInvalidArgument,
              "sampling.step: " + numberText(step) + " gives " + numberText(diagonal / step) + " samples across " +
                  across + " (" + numberText(diagonal) + "); at most " + numberText(kMaxSamplesPerRay) +
                  " are allowed, so the step must be at least " + numberText(diagonal / kMaxSamplesPerRay));
}

}  // namespace

CameraSpec automaticCamera(const GridGeometry& grid, int width, int height) {
  return automaticCamera(grid.domainMin(), grid.domainMax(), grid.minSpacing(), width, height);
}

CameraSpec automaticCamera(Vec3 lo, Vec3 hi, double minSpacing, int width, int height) {
  constexpr double kFovYDeg = 30, kElevationDeg = 20, kAzimuthDeg = 30, kMargin = 1.05;
  constexpr double kDeg = std::numbers::pi / 180;

  // Fit the domain's bounding sphere, plus a margin, into the narrower of
  // the two fields of view. A one-node domain is a point: give it half a voxel.
  const double radius =
      kMargin * std::max(0.5 * length(hi - lo), 0.5 * minSpacing);
  const double halfFovY = 0.5 * kFovYDeg * kDeg;
  const double aspect = double(width) / double(height);
  const double halfFovX = std::atan(std::tan(halfFovY) * aspect);
  const double distance = radius / std::sin(std::min(halfFovY, halfFovX));

  // From the -y side, turned by the azimuth about +z towards +x, raised by the elevation.
  const double el = kElevationDeg * kDeg, az = kAzimuthDeg * kDeg;
  const Vec3 towardsEye{std::cos(el) * std::sin(az), -std::cos(el) * std::cos(az), std::sin(el)};

  CameraSpec cam;
  cam.projection = Projection::kPerspective;
  cam.fovYDeg = kFovYDeg;
  cam.lookAt = (lo + hi) * 0.5;
  cam.eye = cam.lookAt + towardsEye * distance;
  cam.up = {0, 0, 1};
  cam.height = 0;
  cam.automatic = false;
  return cam;
}

void resolveDefaults(Scene& scene, const GridGeometry& grid) {
  grid.validate("volume");
  const double voxel = grid.minSpacing();
  for (SceneVolume& v : scene.volumes)
    if (v.transfer.unitDistance == 0) v.transfer.unitDistance = voxel;
  if (scene.sampling.step == 0) scene.sampling.step = 0.5 * voxel;
  checkSamplesPerRay(scene.sampling.step, length(grid.domainMax() - grid.domainMin()), "the domain's diagonal");
  if (scene.camera.automatic) scene.camera = automaticCamera(grid, scene.image.width, scene.image.height);
  if (scene.shading.automatic) {
    // Gradients need three dimensions: a slice or a line stays unshaded.
    scene.shading.enabled = grid.dims.x > 1 && grid.dims.y > 1 && grid.dims.z > 1;
    scene.shading.automatic = false;
  }
}

void resolveDefaults(Scene& scene, const std::vector<GridGeometry>& grids) {
  if (grids.size() != scene.volumes.size())
    throw Error(ErrorCode::kInternal, "resolveDefaults: " + std::to_string(grids.size()) + " grids for " +
                                          std::to_string(scene.volumes.size()) + " volumes");
  if (grids.size() == 1) return resolveDefaults(scene, grids.front());
  // Each volume's unit distance is its own voxel; the step, the camera and
  // the step limit are over all of them (visible or not, so that showing
  // or hiding one moves nothing).
  double voxel = 0;
  Vec3 lo, hi;
  bool solid = true;
  for (std::size_t i = 0; i < grids.size(); ++i) {
    const GridGeometry& grid = grids[i];
    grid.validate("volumes[" + std::to_string(i) + "] '" + scene.volumes[i].name + "'");
    if (scene.volumes[i].transfer.unitDistance == 0) scene.volumes[i].transfer.unitDistance = grid.minSpacing();
    voxel = i == 0 ? grid.minSpacing() : std::min(voxel, grid.minSpacing());
    for (int a = 0; a < 3; ++a) {
      lo[a] = i == 0 ? grid.domainMin()[a] : std::min(lo[a], grid.domainMin()[a]);
      hi[a] = i == 0 ? grid.domainMax()[a] : std::max(hi[a], grid.domainMax()[a]);
    }
    solid = solid && grid.dims.x > 1 && grid.dims.y > 1 && grid.dims.z > 1;
  }
  if (scene.sampling.step == 0) scene.sampling.step = 0.5 * voxel;
  checkSamplesPerRay(scene.sampling.step, length(hi - lo), "the diagonal of the volumes' union");
  if (scene.camera.automatic) scene.camera = automaticCamera(lo, hi, voxel, scene.image.width, scene.image.height);
  if (scene.shading.automatic) {
    scene.shading.enabled = solid;
    scene.shading.automatic = false;
  }
}

TransferFunctionSpec rampTransfer(double min, double max) {
  if (!(max > min)) max = min + 1;
  // Clear below the first tenth of the range: air and scanner noise fill
  // most of a CT or MRI box, and a ramp from the very bottom turns them
  // into a haze that hides the head (the CT head rendered grey to the
  // box's edges so).
  constexpr double kClearFraction = 0.1;
  TransferFunctionSpec tf;
  tf.points = {{min, 1, 1, 1, 0}, {min + kClearFraction * (max - min), 1, 1, 1, 0}, {max, 1, 1, 1, 1}};
  return tf;
}

void resolveDataDefaults(TransferFunctionSpec& transfer, double min, double max) {
  if (transfer.automatic) {
    const double unit = transfer.unitDistance;
    transfer = rampTransfer(min, max);
    transfer.unitDistance = unit;
  } else if (transfer.rescaleToData && !transfer.points.empty()) {
    // x -> min + (x - x0) * (max - min) / (x1 - x0); a one-scalar preset
    // has no span to stretch and moves to min.
    const double x0 = transfer.points.front().scalar, x1 = transfer.points.back().scalar;
    const double scale = x1 > x0 ? (max - min) / (x1 - x0) : 0;
    for (TransferPoint& p : transfer.points) p.scalar = min + (p.scalar - x0) * scale;
    transfer.points.back().scalar = x1 > x0 ? max : min;  // exact, whatever the rounding
  }
  transfer.rescaleToData = false;
}

}  // namespace pvr::core
