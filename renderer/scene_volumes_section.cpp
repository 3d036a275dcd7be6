// The scene's "volumes" section: several named volumes, each with its own
// transfer function and visibility. The single-volume form ("volume" +
// "transfer_function") is the one-element list named "volume".
#include <set>

#include "scene_json.h"
#include "scene_sections.h"

namespace pvr::core {

using namespace scene_json;

namespace {

// The keys of an entry that are not the volume section's own.
constexpr const char* kName = "name";
constexpr const char* kTransfer = "transfer_function";
constexpr const char* kVisible = "visible";

SceneVolume parseEntry(const json& v, const std::string& path, const std::string& baseDir) {
  requireObject(v, path, {kName, "file", "procedural", "computation", "dims", "spacing", kTransfer, kVisible});
  SceneVolume out;
  const json* name = find(v, kName);
  if (!name) fail(childPath(path, kName), "missing (every volume of \"volumes\" has a name)");
  out.name = asString(*name, childPath(path, kName));
  if (out.name.empty()) fail(childPath(path, kName), "must not be empty");
  json volumeKeys = v;
  for (const char* key : {kName, kTransfer, kVisible}) volumeKeys.erase(key);
  out.source = parseVolume(volumeKeys, baseDir, path);
  const json* tf = find(v, kTransfer);
  out.transfer = tf ? parseTransfer(*tf, baseDir, childPath(path, kTransfer)) : defaultTransfer();
  if (const json* visible = find(v, kVisible)) out.visible = asBool(*visible, childPath(path, kVisible));
  return out;
}

}  // namespace

std::vector<SceneVolume> parseVolumes(const json& v, const std::string& baseDir) {
  const std::string path = "volumes";
  if (!v.is_array()) fail(path, "must be an array of volumes, got " + describeValue(v));
  if (v.empty()) fail(path, "needs at least one volume");
  std::vector<SceneVolume> volumes;
  std::set<std::string> names;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string p = indexPath(path, i);
    volumes.push_back(parseEntry(v[i], p, baseDir));
    if (!names.insert(volumes.back().name).second)
      fail(childPath(p, kName), "'" + volumes.back().name + "' names an earlier volume too; names must be unique");
  }
  return volumes;
}

json volumesToJson(const std::vector<SceneVolume>& volumes) {
  json out = json::array();
  for (const SceneVolume& v : volumes) {
    json entry = volumeToJson(v.source);
    entry[kName] = v.name;
    if (!v.transfer.automatic) entry[kTransfer] = transferToJson(v.transfer);
    entry[kVisible] = v.visible;
    out.push_back(std::move(entry));
  }
  return out;
}

std::map<std::string, double> parseParameters(const json& v) {
  const std::string path = "parameters";
  if (!v.is_object()) fail(path, "must be an object {name: number, ...}, got " + describeValue(v));
  std::map<std::string, double> out;
  for (const auto& [name, value] : v.items()) {
    if (name.empty()) fail(path, "a parameter name must not be empty");
    out[name] = asNumber(value, childPath(path, name));
  }
  return out;
}

}  // namespace pvr::core
