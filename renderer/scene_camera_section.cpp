// The scene's "camera" section. Without it the camera is automatic
// (scene_defaults.cpp); with it, eye and look_at are required.
#include "scene_json.h"
#include "scene_sections.h"

namespace pvr::core {

using namespace scene_json;

CameraSpec parseCameraSection(const json& v) {
  const std::string path = "camera";
  requireObject(v, path, {"projection", "eye", "look_at", "up", "height", "fov_y_deg"});
  CameraSpec cam;
  cam.automatic = false;

  if (const json* p = find(v, "projection")) {
    const std::string name = asString(*p, path + ".projection");
    if (name == "orthographic") cam.projection = Projection::kOrthographic;
    else if (name == "perspective") cam.projection = Projection::kPerspective;
    else fail(path + ".projection", "must be \"orthographic\" or \"perspective\", got \"" + name + "\"");
  }
  for (const char* key : {"eye", "look_at"})
    if (!find(v, key)) fail(childPath(path, key), "missing (a camera needs eye and look_at)");
  cam.eye = asVec3(v["eye"], path + ".eye");
  cam.lookAt = asVec3(v["look_at"], path + ".look_at");
  if (const json* up = find(v, "up")) cam.up = asVec3(*up, path + ".up");

  // The key the projection does not use is still checked and kept, so a
  // document can switch projection by one word and print back unchanged.
  if (const json* h = find(v, "height")) cam.height = positive(*h, path + ".height");
  if (const json* f = find(v, "fov_y_deg")) {
    cam.fovYDeg = asNumber(*f, path + ".fov_y_deg");
    if (!(cam.fovYDeg > 0 && cam.fovYDeg < 180))
      fail(path + ".fov_y_deg", "must be in (0, 180), got " + numberText(cam.fovYDeg));
  }
  if (cam.projection == Projection::kOrthographic && !find(v, "height"))
    fail(path + ".height", "missing (an orthographic camera needs its view height)");

  // Geometry the camera basis needs: a view direction and an up not along it.
  const Vec3 dir = cam.lookAt - cam.eye;
  if (!(length(dir) > 0)) fail(path + ".eye", "must differ from camera.look_at");
  if (!(length(cam.up) > 0)) fail(path + ".up", "must not be the zero vector");
  const double sine = length(cross(normalize(dir), normalize(cam.up)));
  if (!(sine > 1e-6)) fail(path + ".up", "must not be parallel to the view direction (look_at - eye)");
  return cam;
}

json cameraSectionToJson(const CameraSpec& camera) {
  // Height 0 of a perspective camera means "not given".
  json out = {{"projection", camera.projection == Projection::kOrthographic ? "orthographic" : "perspective"},
              {"eye", toJson(camera.eye)},
              {"look_at", toJson(camera.lookAt)},
              {"up", toJson(camera.up)},
              {"fov_y_deg", camera.fovYDeg}};
  if (camera.height > 0 || camera.projection == Projection::kOrthographic) out["height"] = camera.height;
  return out;
}

}  // namespace pvr::core
