// The scene document as a whole: its sections in, its sections out.
#include "scene.h"

#include <filesystem>

#include "error.h"
#include "io/json_file.h"
#include "scene_json.h"
#include "scene_sections.h"

namespace pvr::core {

using namespace scene_json;

Scene parseScene(const json& doc, const std::string& baseDir) {
  requireObject(doc, "", {"volume", "volumes", "timestep", "transfer_function", "parameters", "camera", "image",
                          "sampling", "shading"});
  Scene scene;
  const json* volume = find(doc, "volume");
  const json* volumes = find(doc, "volumes");
  const json* tf = find(doc, "transfer_function");
  if (volume && volumes) fail("volumes", "give \"volume\" (one volume) or \"volumes\" (several), not both");
  if (volumes) {
    if (tf) fail("transfer_function", "a \"volumes\" scene gives each volume its own transfer_function");
    scene.volumes = parseVolumes(*volumes, baseDir);
  } else {
    if (!volume) fail("volume", "missing (every scene names its volume, or its \"volumes\")");
    SceneVolume& only = scene.volumes.front();
    only.source = parseVolume(*volume, baseDir);
    only.transfer = tf ? parseTransfer(*tf, baseDir) : defaultTransfer();
  }
  if (const json* v = find(doc, "timestep")) {
    const int step = parseTimestep(*v);
    for (SceneVolume& each : scene.volumes) each.source.timestep = step;
  }
  if (const json* v = find(doc, "parameters")) scene.parameters = parseParameters(*v);
  if (const json* v = find(doc, "camera")) scene.camera = parseCameraSection(*v);
  if (const json* v = find(doc, "image")) scene.image = parseImage(*v);
  if (const json* v = find(doc, "sampling")) scene.sampling = parseSampling(*v);
  // Without "shading.enabled" the data decides (resolveDefaults).
  scene.shading.automatic = true;
  if (const json* v = find(doc, "shading")) scene.shading = parseShading(*v);
  return scene;
}

Scene loadSceneFile(const std::string& path) {
  const json doc = readJsonFile(path);
  // Absolute, so the paths it resolves stay valid wherever the scene goes next.
  const std::string baseDir = std::filesystem::absolute(std::filesystem::path(path)).parent_path().string();
  try {
    return parseScene(doc, baseDir);
  } catch (const Error& e) {
    throw Error(e.code(), path + ": " + e.what());
  }
}

json sceneToJson(const Scene& s) {
  // A scene of one visible volume named "volume" prints in the single form.
  const SceneVolume& first = s.volumes.front();
  json doc;
  if (s.volumes.size() == 1 && first.name == SceneVolume{}.name && first.visible) {
    doc["volume"] = volumeToJson(first.source);
    // A transfer function left to the data is the absent section.
    if (!first.transfer.automatic) doc["transfer_function"] = transferToJson(first.transfer);
  } else {
    doc["volumes"] = volumesToJson(s.volumes);
  }
  doc["timestep"] = first.source.timestep;
  doc["image"] = imageToJson(s.image);
  doc["sampling"] = samplingToJson(s.sampling);
  doc["shading"] = shadingToJson(s.shading);
  if (!s.parameters.empty()) doc["parameters"] = s.parameters;
  // An automatic camera is the absent section.
  if (!s.camera.automatic) doc["camera"] = cameraSectionToJson(s.camera);
  return doc;
}

}  // namespace pvr::core
