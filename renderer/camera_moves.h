// Camera moves: zoom, pan, orbit and standard views, each taking the camera
// in force to a new one. The one place for this arithmetic: the server
// applies a client's moves (SetScene "camera_moves", docs/scene.md) to the
// camera it renders with, automatic or set, so a client needs no copy of
// the camera to move it, and pvr-render, pvrsh and the GUI agree.
//
// Every move keeps the projection and returns a camera that is not
// automatic; each throws pvr::Error (kInvalidArgument) naming the move for
// a bad value or for a result the camera refuses (looking along up).
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json_fwd.hpp>

#include "scene.h"

namespace pvr::core {

// Magnifies the image by `factor` (> 0) about its centre: the tangent of
// half the vertical field of view, and the view height, are divided by it.
// The eye does not move (a zoom, not a dolly).
CameraSpec zoomCamera(const CameraSpec& camera, double factor);

// Moves eye and look_at together by `dx` view widths to the right and `dy`
// view heights up (the view measured in the plane of look_at; `aspect` is
// the image's width / height): the volume moves the other way on screen.
CameraSpec panCamera(const CameraSpec& camera, double dx, double dy, double aspect);

// Orbits the eye about look_at: azimuth turns it right-handedly about the
// up vector, elevation raises it towards the up vector (about the axis
// across the view). The up vector is kept; an elevation that would look
// along it is refused.
CameraSpec azimuthCamera(const CameraSpec& camera, double degrees);
CameraSpec elevationCamera(const CameraSpec& camera, double degrees);

// The names of the standard views, in the order a GUI shows them:
// "+x" looks along +x (ParaView's "set view direction to +X"), ... "-z";
// "iso" looks along (-1, 1, -1), from the +x, -y, +z side as the automatic
// camera does. Up is +z, except +y for the views along z.
inline constexpr std::string_view kStandardViews[] = {"+x", "-x", "+y", "-y", "+z", "-z", "iso"};

// The camera looking at the same look_at from the same distance along the
// standard view `name`; an unknown name is an error listing the known ones.
CameraSpec standardView(const CameraSpec& camera, std::string_view name);

// Applies a "camera_moves" array (docs/scene.md): objects of one key each,
// {"zoom": F}, {"pan": [DX, DY]}, {"azimuth": DEG}, {"elevation": DEG},
// {"view": NAME}, in order. Errors name the entry: "camera_moves[1].zoom: ...".
CameraSpec applyCameraMoves(const CameraSpec& camera, const nlohmann::json& moves, double aspect);

}  // namespace pvr::core
