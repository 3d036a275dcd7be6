// The camera part of a SetScene patch, applied to the camera in force.
//
// A client moves the camera without holding a copy of it: "camera" keys
// (eye, fov_y_deg, ...) and "camera_moves" (zoom, pan, orbit, standard
// views; renderer/camera_moves.h) are applied on the server to the camera
// the session renders with, the automatic one included. Keys merge into a
// set camera as any scene key does; keys without eye and look_at while the
// camera is automatic, and every move, need the camera in force, which
// exists once a dataset is loaded (docs/scene.md, "Moving the camera").
#pragma once

#include <nlohmann/json.hpp>

#include "scene.h"

namespace pvr::node {

struct CameraRequest {
  bool reset = false;                               // "camera": null: back to the automatic camera
  nlohmann::json keys = nlohmann::json::object();   // "camera": {...}, the keys given
  nlohmann::json moves = nlohmann::json::array();   // "camera_moves", in order
  bool empty() const { return !reset && keys.empty() && moves.empty(); }
};

// Takes "camera" and "camera_moves" out of a SetScene patch. Throws
// pvr::Error when "camera" is neither an object nor null.
CameraRequest takeCameraRequest(nlohmann::json& patch);

// Whether the request merges into the scene document `doc` as a plain
// patch would: no moves, and a reset, or keys over a camera the document
// sets, or keys holding eye and look_at.
bool mergesIntoDocument(const CameraRequest& request, const nlohmann::json& doc);

// The request as it goes back into a patch that merges as it is.
nlohmann::json asPatch(const CameraRequest& request);

// The "camera" section the request makes of the camera in force: starting
// from `automatic` after a reset, else from `inForce`, the keys merged,
// then the moves applied (`aspect`: the image's width / height). Throws
// pvr::Error naming the key or move a camera refuses.
nlohmann::json cameraSectionAfter(const CameraRequest& request, const core::CameraSpec& inForce,
                                  const core::CameraSpec& automatic, double aspect);

}  // namespace pvr::node
