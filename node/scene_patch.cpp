#include "scene_patch.h"

#include <algorithm>
#include <climits>
#include <cstdlib>
#include <cstring>

#include <unistd.h>

#include "catalog_listing.h"
#include "io/data_directory.h"
#include "io/volume_io.h"
#include "scene.h"
#include "wire_error.h"

namespace pvr::node {

namespace {

using proto::ErrorCode;
using proto::ProtocolError;

// The real path of `dataset` if it is a regular file inside `dataDir`.
std::optional<std::string> resolveDataset(const std::string& dataset, const std::string& dataDir) {
  if (dataDir.empty()) return std::nullopt;
  return core::DataDirectory(dataDir).confine(dataset);
}

// Server-side ParaView presets: a client names one by its file name in the
// data directory's presets/ folder (its own presets it sends as content,
// "paraview"). Rewrites each "paraview_preset" of the document to the real
// path, or returns the error that refuses it: the same words whether the
// file is missing, outside the folder or not a regular file.
std::optional<ProtocolError> resolvePresets(nlohmann::json& doc, const std::string& dataDir) {
  const auto resolve = [&](nlohmann::json& tf, const std::string& where) -> std::optional<ProtocolError> {
    if (!tf.is_object() || !tf.contains("paraview_preset") || !tf["paraview_preset"].is_string()) return std::nullopt;
    const std::string named = tf["paraview_preset"].get<std::string>();
    std::optional<std::string> real;
    const std::string folder = dataDir + "/" + kPresetFolder;
    if (!dataDir.empty() && ::access(folder.c_str(), X_OK) == 0) real = core::DataDirectory(folder).confine(named);
    if (!real)
      return ProtocolError{ErrorCode::kBadArgument, where + ".paraview_preset: no preset '" + named +
                                                        "' in the data directory's " + kPresetFolder +
                                                        "/ folder (send your own preset as \"paraview\")"};
    tf["paraview_preset"] = *real;
    return std::nullopt;
  };
  if (doc.contains("transfer_function"))
    if (auto e = resolve(doc["transfer_function"], "scene.transfer_function")) return e;
  if (doc.contains("volumes") && doc["volumes"].is_array())
    for (std::size_t i = 0; i < doc["volumes"].size(); ++i)
      if (doc["volumes"][i].is_object() && doc["volumes"][i].contains("transfer_function"))
        if (auto e = resolve(doc["volumes"][i]["transfer_function"],
                             "scene.volumes[" + std::to_string(i) + "].transfer_function"))
          return e;
  return std::nullopt;
}

// A volume entry of a patch names its data by "dataset" (resolved here to
// the "file" the ranks open), never by "file". `where` names the entry.
std::optional<ProtocolError> resolveEntryDataset(nlohmann::json& entry, const std::string& where,
                                                 const std::string& dataDir) {
  if (!entry.is_object()) return std::nullopt;  // the scene parser names what is wrong
  if (entry.contains("file"))
    return ProtocolError{ErrorCode::kBadArgument, where + ".file: name a dataset, not a volume file"};
  const auto dataset = entry.find("dataset");
  if (dataset == entry.end()) return std::nullopt;
  if (!dataset->is_string())
    return ProtocolError{ErrorCode::kBadArgument, where + ".dataset: must be a dataset name (a string)"};
  const std::string name = dataset->get<std::string>();
  auto file = resolveDataset(name, dataDir);
  // A catalog stem ("head" for head.nhdr), as `list datasets` names it and
  // pvrd resolves SetScene's dataset field (pvrd/dataset_names.h).
  if (!file && !dataDir.empty())
    for (const CatalogDataset& d : listCatalog(dataDir).datasets)
      if (d.name == name) file = resolveDataset(d.file, dataDir);
  if (!file)
    return ProtocolError{ErrorCode::kDatasetNotFound, where + ".dataset: no dataset '" + name + "' in the data directory"};
  entry.erase("dataset");
  entry["file"] = *file;
  return std::nullopt;
}

// The keys of a volume entry that say where its data comes from.
constexpr const char* kDataKeys[] = {"file", "procedural", "computation", "dims", "spacing"};

// The session's volumes as a list: a scene in the single form becomes the
// one-element list named "volume" (docs/protocol.md, SetScene).
nlohmann::json& volumeList(nlohmann::json& doc) {
  if (doc.contains("volumes") && doc["volumes"].is_array()) return doc["volumes"];
  nlohmann::json list = nlohmann::json::array();
  if (doc.contains("volume") && doc["volume"].is_object()) {
    nlohmann::json entry = doc["volume"];
    entry["name"] = "volume";
    if (doc.contains("transfer_function")) entry["transfer_function"] = doc["transfer_function"];
    list.push_back(std::move(entry));
  }
  doc.erase("volume");
  doc.erase("transfer_function");
  doc["volumes"] = std::move(list);
  return doc["volumes"];
}

// Applies a patch's "volumes" to doc: an array replaces the list, an
// object patches volumes by name (docs/protocol.md, SetScene).
std::optional<ProtocolError> patchVolumes(nlohmann::json& doc, nlohmann::json volumes, const std::string& dataDir) {
  if (volumes.is_array()) {
    for (std::size_t i = 0; i < volumes.size(); ++i)
      if (auto e = resolveEntryDataset(volumes[i], "scene.volumes[" + std::to_string(i) + "]", dataDir)) return e;
    doc.erase("volume");
    doc.erase("transfer_function");
    doc["volumes"] = std::move(volumes);
    return std::nullopt;
  }
  if (!volumes.is_object())
    return ProtocolError{ErrorCode::kBadArgument,
                         "scene.volumes: must be a list of volumes or an object {NAME: patch or null}"};
  nlohmann::json& list = volumeList(doc);
  for (auto& [name, patch] : volumes.items()) {
    const std::string where = "scene.volumes." + name;
    auto at = std::find_if(list.begin(), list.end(), [&](const nlohmann::json& v) {
      return v.is_object() && v.contains("name") && v["name"] == name;
    });
    if (patch.is_null()) {
      if (at == list.end()) return ProtocolError{ErrorCode::kBadArgument, where + ": no volume '" + name + "' to remove"};
      if (list.size() == 1)
        return ProtocolError{ErrorCode::kBadArgument,
                             where + ": cannot remove the last volume '" + name + "'; name another dataset"};
      list.erase(at);
      continue;
    }
    if (!patch.is_object())
      return ProtocolError{ErrorCode::kBadArgument, where + ": must be an object (a volume's keys) or null (remove it)"};
    if (auto e = resolveEntryDataset(patch, where, dataDir)) return e;
    bool namesData = false;
    for (const char* key : {"file", "procedural", "computation"}) namesData |= patch.contains(key);
    if (at == list.end()) {
      if (!namesData)
        return ProtocolError{ErrorCode::kBadArgument,
                             where + ": a new volume names its data (\"dataset\" or \"procedural\")"};
      patch["name"] = name;
      list.push_back(std::move(patch));
      continue;
    }
    // New data replaces the old data's keys; a transfer function is
    // replaced whole, as a section of its own.
    if (namesData)
      for (const char* key : kDataKeys) at->erase(key);
    if (patch.contains("transfer_function")) {
      (*at)["transfer_function"] = patch["transfer_function"];
      patch.erase("transfer_function");
    }
    at->merge_patch(patch);
  }
  return std::nullopt;
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
    if (auto deep = proto::checkJsonDepth(request.sceneJson, "scene")) return *deep;
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
      if (volume->is_object() && volume->contains("file") && !(*volume)["file"].is_null())
        return ProtocolError{ErrorCode::kBadArgument, "scene.volume.file: name a dataset, not a volume file"};
      if (volume->is_null() && current.hasVolume())
        return ProtocolError{ErrorCode::kBadArgument, "scene.volume: cannot be removed; name another dataset"};
      // "volume": exactly this one volume.
      if (volume->is_object()) next.doc.erase("volumes");
    }
    if (const auto volumes = patch.find("volumes"); volumes != patch.end()) {
      if (auto refused = patchVolumes(next.doc, *volumes, dataDir)) return *refused;
      patch.erase("volumes");
    }
    next.doc.merge_patch(patch);
  }
  if (auto refused = resolvePresets(next.doc, dataDir)) return *refused;
  if (!request.dataset.empty()) {
    const auto file = resolveDataset(request.dataset, dataDir);
    if (!file)
      return ProtocolError{ErrorCode::kDatasetNotFound, "no dataset '" + request.dataset + "' in the data directory"};
    next.doc["volume"] = {{"file", *file}};
    next.doc.erase("volumes");  // a dataset is exactly this one volume
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
