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
  requireObject(doc, "", {"volume", "timestep", "transfer_function", "camera", "image", "sampling", "shading"});
  Scene scene;
  const json* volume = find(doc, "volume");
  if (!volume) fail("volume", "missing (every scene names its volume)");
  scene.volume = parseVolume(*volume, baseDir);
  if (const json* v = find(doc, "timestep")) scene.volume.timestep = parseTimestep(*v);
  const json* tf = find(doc, "transfer_function");
  scene.transfer = tf ? parseTransfer(*tf, baseDir) : defaultTransfer();
  if (const json* v = find(doc, "camera")) scene.camera = parseCameraSection(*v);
  if (const json* v = find(doc, "image")) scene.image = parseImage(*v);
  if (const json* v = find(doc, "sampling")) scene.sampling = parseSampling(*v);
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
  json doc = {{"volume", volumeToJson(s.volume)},
              {"timestep", s.volume.timestep},
              {"transfer_function", transferToJson(s.transfer)},
              {"image", imageToJson(s.image)},
              {"sampling", samplingToJson(s.sampling)},
              {"shading", shadingToJson(s.shading)}};
  // An automatic camera is the absent section.
  if (!s.camera.automatic) doc["camera"] = cameraSectionToJson(s.camera);
  return doc;
}

}  // namespace pvr::core
