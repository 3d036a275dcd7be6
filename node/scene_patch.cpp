#include "scene_patch.h"

#include <climits>
#include <cstdlib>
#include <cstring>

#include "io/volume_io.h"
#include "scene.h"
#include "wire_error.h"

namespace pvr::node {

namespace {

using proto::ErrorCode;
using proto::ProtocolError;

// The real path of `dataset` if it lies inside `dataDir`.
std::optional<std::string> resolveDataset(const std::string& dataset, const std::string& dataDir) {
  char real[PATH_MAX];
  const std::string wanted = dataset[0] == '/' ? dataset : dataDir + "/" + dataset;
  if (dataDir.empty() || !::realpath(wanted.c_str(), real)) return std::nullopt;
  if (std::strncmp(real, dataDir.c_str(), dataDir.size()) != 0 || real[dataDir.size()] != '/') return std::nullopt;
  return std::string(real);
}

// What the scene parser checks a document against before a volume is named:
// any valid volume section does, since parsing does not open it.
nlohmann::json standInVolume() {
  return {{"procedural", core::proceduralNames().front()}, {"dims", {2, 2, 2}}};
}

}  // namespace

std::variant<SessionScene, ProtocolError> patchScene(const SessionScene& current, const proto::SetScene& request,
                                                     const std::string& dataDir) {
  SessionScene next = current;
  if (!request.sceneJson.empty()) {
    nlohmann::json patch = nlohmann::json::parse(request.sceneJson, nullptr, false);
    if (patch.is_discarded() || !patch.is_object())
      return ProtocolError{ErrorCode::kBadArgument, "scene: not a JSON object"};
    if (const auto runtime = patch.find("runtime"); runtime != patch.end()) {
      // null resets the settings, as merging null removes any other key.
      if (runtime->is_null()) next.runtime = nlohmann::json::object();
      else next.runtime.merge_patch(*runtime);
      patch.erase("runtime");
    }
    if (const auto volume = patch.find("volume"); volume != patch.end()) {
      if (volume->is_object() && volume->contains("file"))
        return ProtocolError{ErrorCode::kBadArgument, "scene.volume.file: name a dataset, not a volume file"};
      if (volume->is_null() && current.hasVolume())
        return ProtocolError{ErrorCode::kBadArgument, "scene.volume: cannot be removed; name another dataset"};
    }
    next.doc.merge_patch(patch);
  }
  if (!request.dataset.empty()) {
    const auto file = resolveDataset(request.dataset, dataDir);
    if (!file)
      return ProtocolError{ErrorCode::kDatasetNotFound, "no dataset '" + request.dataset + "' in the data directory"};
    next.doc["volume"] = {{"file", *file}};
  }

  // The merged whole, as the ranks will read it.
  try {
    next.settings = settingsFrom(next.runtime);
    nlohmann::json probe = next.doc;
    if (!next.hasVolume()) probe["volume"] = standInVolume();
    const core::Scene scene = core::parseScene(probe, dataDir);
    if (auto error = proto::checkImageSize(std::uint64_t(scene.image.width), std::uint64_t(scene.image.height),
                                           next.settings.format))
      return *error;
  } catch (const Error& e) {
    return wireError(e);
  }
  return next;
}

}  // namespace pvr::node
