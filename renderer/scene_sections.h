// The sections of a scene document, each read and written by one pair of
// functions (parseScene and sceneToJson call them). Internal to the
// renderer; the camera's pair is public (scene.h). Readers throw
// pvr::Error naming the key path (scene_json.h); writers write every key
// of their section, except the values that mean "not set yet" (docs/scene.md,
// "Printing a scene").
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "scene.h"

namespace pvr::core {

// "volume" (or the volume keys of a "volumes" entry at `path`): relative
// file paths resolve against baseDir.
VolumeSpec parseVolume(const nlohmann::json& section, const std::string& baseDir,
                       const std::string& path = "volume");
nlohmann::json volumeToJson(const VolumeSpec& volume);

// "timestep": a 0-based step of a time series, 0..INT32_MAX. Whether the
// volume has that step is checkTimestep's to say (scene_volume.h), once the
// volume is open.
int parseTimestep(const nlohmann::json& value);

// "transfer_function": points, a ParaView preset file (relative to baseDir)
// or an inline preset; defaultTransfer() is the scene without the section.
TransferFunctionSpec parseTransfer(const nlohmann::json& section, const std::string& baseDir,
                                   const std::string& path = "transfer_function");
TransferFunctionSpec defaultTransfer();
nlohmann::json transferToJson(const TransferFunctionSpec& transfer);

// "volumes": several named volumes, each with its transfer function
// (docs/scene.md, "Several volumes"); and the single-volume form
// ("volume" + "transfer_function") they generalise.
std::vector<SceneVolume> parseVolumes(const nlohmann::json& section, const std::string& baseDir);
nlohmann::json volumesToJson(const std::vector<SceneVolume>& volumes);

// "parameters": steering parameters, name -> finite number.
std::map<std::string, double> parseParameters(const nlohmann::json& section);

// "image", "sampling", "shading": how to render.
ImageSpec parseImage(const nlohmann::json& section);
nlohmann::json imageToJson(const ImageSpec& image);
SamplingSpec parseSampling(const nlohmann::json& section);
nlohmann::json samplingToJson(const SamplingSpec& sampling);
ShadingSpec parseShading(const nlohmann::json& section);
nlohmann::json shadingToJson(const ShadingSpec& shading);

}  // namespace pvr::core
