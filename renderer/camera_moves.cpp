#include "camera_moves.h"

#include <cmath>
#include <numbers>

#include "error.h"
#include "scene_json.h"

namespace pvr::core {

namespace {

using namespace scene_json;

constexpr double kRadiansPerDegree = std::numbers::pi / 180;

// The camera's unit right and up vectors, up made square to the view
// (the spec's up is only a hint of where up is).
struct ViewBasis {
  Vec3 forward, right, up;
};

ViewBasis basisOf(const CameraSpec& c) {
  ViewBasis b;
  b.forward = normalize(c.lookAt - c.eye);
  b.right = normalize(cross(b.forward, c.up));
  b.up = cross(b.right, b.forward);
  return b;
}

// The check parseCameraSection makes, for a camera a move produced.
void requireViewAcrossUp(const CameraSpec& c, const std::string& move) {
  const double sine = length(cross(normalize(c.lookAt - c.eye), normalize(c.up)));
  if (!(sine > 1e-6)) fail(move, "would look along the up vector; turn less, or set another up");
}

CameraSpec fixed(CameraSpec c) {
  c.automatic = false;
  return c;
}

}  // namespace

CameraSpec zoomCamera(const CameraSpec& camera, double factor) {
  if (!(factor > 0) || !std::isfinite(factor)) fail("zoom", "must be a finite number > 0, got " + numberText(factor));
  CameraSpec c = fixed(camera);
  const double halfTan = std::tan(0.5 * c.fovYDeg * kRadiansPerDegree) / factor;
  c.fovYDeg = 2 * std::atan(halfTan) / kRadiansPerDegree;
  if (!(c.fovYDeg > 0)) fail("zoom", numberText(factor) + " leaves no field of view");
  // Both are kept in step, so switching projection keeps the zoom.
  c.height = camera.height / factor;
  return c;
}

CameraSpec panCamera(const CameraSpec& camera, double dx, double dy, double aspect) {
  if (!std::isfinite(dx) || !std::isfinite(dy)) fail("pan", "needs finite fractions of the view");
  CameraSpec c = fixed(camera);
  const ViewBasis b = basisOf(camera);
  // The view's height where look_at is: what the image shows top to bottom there.
  const double viewHeight = camera.projection == Projection::kOrthographic
                                ? camera.height
                                : 2 * length(camera.lookAt - camera.eye) *
                                      std::tan(0.5 * camera.fovYDeg * kRadiansPerDegree);
  const Vec3 shift = b.right * (dx * viewHeight * aspect) + b.up * (dy * viewHeight);
  c.eye = camera.eye + shift;
  c.lookAt = camera.lookAt + shift;
  return c;
}

CameraSpec azimuthCamera(const CameraSpec& camera, double degrees) {
  if (!std::isfinite(degrees)) fail("azimuth", "needs a finite angle in degrees");
  CameraSpec c = fixed(camera);
  c.eye = camera.lookAt + rotateAbout(camera.eye - camera.lookAt, normalize(camera.up), degrees * kRadiansPerDegree);
  return c;
}

CameraSpec elevationCamera(const CameraSpec& camera, double degrees) {
  if (!std::isfinite(degrees)) fail("elevation", "needs a finite angle in degrees");
  CameraSpec c = fixed(camera);
  // Turning about -right raises the eye towards up: (-right) x (-forward) = up.
  const Vec3 axis = -basisOf(camera).right;
  c.eye = camera.lookAt + rotateAbout(camera.eye - camera.lookAt, axis, degrees * kRadiansPerDegree);
  requireViewAcrossUp(c, "elevation");
  return c;
}

CameraSpec standardView(const CameraSpec& camera, std::string_view name) {
  struct View {
    std::string_view name;
    Vec3 direction, up;
  };
  static const View kViews[] = {{"+x", {1, 0, 0}, {0, 0, 1}},  {"-x", {-1, 0, 0}, {0, 0, 1}},
                                {"+y", {0, 1, 0}, {0, 0, 1}},  {"-y", {0, -1, 0}, {0, 0, 1}},
                                {"+z", {0, 0, 1}, {0, 1, 0}},  {"-z", {0, 0, -1}, {0, 1, 0}},
                                {"iso", {-1, 1, -1}, {0, 0, 1}}};
  for (const View& v : kViews) {
    if (v.name != name) continue;
    CameraSpec c = fixed(camera);
    c.eye = camera.lookAt - normalize(v.direction) * length(camera.lookAt - camera.eye);
    c.up = v.up;
    return c;
  }
  fail("view", "must be one of " + joinNames(kStandardViews) + ", got \"" + std::string(name) + "\"");
}

CameraSpec applyCameraMoves(const CameraSpec& camera, const json& moves, double aspect) {
  const std::string path = "camera_moves";
  if (!moves.is_array()) fail(path, "must be an array of moves, got " + describeValue(moves));
  CameraSpec c = camera;
  for (std::size_t i = 0; i < moves.size(); ++i) {
    const std::string at = indexPath(path, i);
    const json& move = moves[i];
    requireObject(move, at, {"zoom", "pan", "azimuth", "elevation", "view"});
    if (move.size() != 1) fail(at, "must hold exactly one move, got " + std::to_string(move.size()));
    const std::string key = move.begin().key();
    const std::string where = childPath(at, key);
    const json& value = move.begin().value();
    // Values are read with the entry's path; a move's own error starts with
    // the move's name ("elevation: ..."), so the entry's path goes before it.
    const auto named = [&](auto&& step) {
      try {
        c = step();
      } catch (const Error& e) {
        throw Error(e.code(), at + "." + e.what());
      }
    };
    if (key == "zoom") {
      const double factor = positive(value, where);
      named([&] { return zoomCamera(c, factor); });
    } else if (key == "pan") {
      if (!value.is_array() || value.size() != 2) fail(where, "must be [DX, DY], got " + describeValue(value));
      const double dx = asNumber(value[0], where + "[0]"), dy = asNumber(value[1], where + "[1]");
      named([&] { return panCamera(c, dx, dy, aspect); });
    } else if (key == "azimuth") {
      const double degrees = asNumber(value, where);
      named([&] { return azimuthCamera(c, degrees); });
    } else if (key == "elevation") {
      const double degrees = asNumber(value, where);
      named([&] { return elevationCamera(c, degrees); });
    } else {
      const std::string name = asString(value, where);
      named([&] { return standardView(c, name); });
    }
  }
  return c;
}

}  // namespace pvr::core
