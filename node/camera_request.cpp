#include "camera_request.h"

#include <cmath>
#include <numbers>

#include "camera_moves.h"
#include "error.h"

namespace pvr::node {

CameraRequest takeCameraRequest(nlohmann::json& patch) {
  CameraRequest request;
  if (const auto camera = patch.find("camera"); camera != patch.end()) {
    if (camera->is_null()) request.reset = true;
    else if (camera->is_object()) request.keys = *camera;
    else throw Error(ErrorCode::kInvalidArgument, "scene.camera: must be an object, or null for the automatic camera");
    patch.erase(camera);
  }
  if (const auto moves = patch.find("camera_moves"); moves != patch.end()) {
    if (!moves->is_array()) throw Error(ErrorCode::kInvalidArgument, "scene.camera_moves: must be an array of moves");
    request.moves = *moves;
    patch.erase(moves);
  }
  return request;
}

bool mergesIntoDocument(const CameraRequest& request, const nlohmann::json& doc) {
  if (!request.moves.empty()) return false;
  if (request.keys.empty()) return true;  // nothing, or a reset: the automatic camera needs no camera in force
  const bool setCamera = doc.contains("camera") && doc["camera"].is_object();
  return setCamera || (request.keys.contains("eye") && request.keys.contains("look_at"));
}

nlohmann::json asPatch(const CameraRequest& request) {
  nlohmann::json patch = nlohmann::json::object();
  if (request.reset) patch["camera"] = nullptr;
  else if (!request.keys.empty()) patch["camera"] = request.keys;
  return patch;
}

nlohmann::json cameraSectionAfter(const CameraRequest& request, const core::CameraSpec& inForce,
                                  const core::CameraSpec& automatic, double aspect) {
  nlohmann::json section = core::cameraSectionToJson(request.reset ? automatic : inForce);
  section.merge_patch(request.keys);
  // Orthographic without a height: the height the perspective view has at
  // look_at, so switching projection keeps what is seen there.
  if (section.value("projection", "") == "orthographic" && !section.contains("height")) {
    const core::CameraSpec c = request.reset ? automatic : inForce;
    section["height"] = 2 * core::length(c.lookAt - c.eye) * std::tan(0.5 * c.fovYDeg * std::numbers::pi / 180);
  }
  const core::CameraSpec merged = core::parseCameraSection(section);
  return core::cameraSectionToJson(core::applyCameraMoves(merged, request.moves, aspect));
}

}  // namespace pvr::node
