#include "steering_patch.h"

#include "computation.h"
#include "scene.h"
#include "wire_error.h"

namespace pvr::node {

namespace {

// The patch as a JSON object; anything else is patchScene's to refuse.
nlohmann::json patchOf(const proto::SetScene& request) {
  if (request.sceneJson.empty() || proto::checkJsonDepth(request.sceneJson, "scene")) return nullptr;
  return nlohmann::json::parse(request.sceneJson, nullptr, false);
}

}  // namespace

bool isSteeringPatch(const proto::Message& m) {
  const auto* request = std::get_if<proto::SetScene>(&m);
  if (!request || !request->dataset.empty()) return false;
  const nlohmann::json patch = patchOf(*request);
  return patch.is_object() && patch.size() == 1 && patch.contains("parameters");
}

std::optional<proto::ProtocolError> checkSteering(const proto::SetScene& request, const SessionScene& next,
                                                  const std::string& dataDir) {
  if (!next.hasVolume()) return std::nullopt;  // checked once a volume is named
  try {
    const core::Scene scene = core::parseScene(next.doc, dataDir);
    const core::VolumeSpec& volume = scene.volumes.front().source;
    if (!volume.computation.empty()) {
      Parameters(computationNamed(volume.computation), scene.parameters);
      return std::nullopt;
    }
    const nlohmann::json patch = patchOf(request);
    if (patch.is_object() && patch.contains("parameters") && !patch["parameters"].is_null() &&
        !patch["parameters"].empty())
      return proto::ProtocolError{proto::ErrorCode::kBadArgument,
                                  "parameters: only a computation volume takes parameters (docs/steering.md); "
                                  "this scene's volume is a " +
                                      std::string(volume.file.empty() ? "procedural volume" : "dataset")};
  } catch (const Error& e) {
    return wireError(e);
  }
  return std::nullopt;
}

}  // namespace pvr::node
