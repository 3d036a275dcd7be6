// The one reader of ParaView transfer-function presets (docs/scene.md,
// "ParaView presets"), for both forms a scene may use:
//   "transfer_function": {"paraview_preset": "bone.json"}   a preset file
//   "transfer_function": {"paraview": <that file's JSON>}    the same, inline
// pvrsh -tfpreset sends a file's JSON inline, so every client reads presets
// with the same rules.
#pragma once

#include <string>

#include <nlohmann/json_fwd.hpp>

#include "scene.h"

namespace pvr::core {

// A preset as ParaView exports it: one preset object, or an array of them
// whose first element is used. "RGBPoints" [x, r, g, b, ...] is required,
// "Points" [x, opacity, midpoint, sharpness, ...] optional (without it,
// opacity ramps from 0 at the first colour scalar to 1 at the last); both
// sorted by x. Values are taken as they are; colour and opacity are merged
// into one list of control points at the union of their scalars, and a jump
// (two knots at one x) in either becomes two points. unitDistance stays 0.
// Throws pvr::Error(kInvalidArgument) whose message starts with the key
// path of the bad value below `path`: "transfer_function.paraview.Points[5]:
// must be in [0, 1], got 1.2".
TransferFunctionSpec paraViewPresetFromJson(const nlohmann::json& preset, const std::string& path);

// Reads a preset file. Errors start with the file's path ("bone.json:
// Points[5]: ..."): kIo when it cannot be read, kBadFile for its content.
TransferFunctionSpec loadParaViewPreset(const std::string& path);

}  // namespace pvr::core
