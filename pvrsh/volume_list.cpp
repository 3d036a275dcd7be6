#include "volume_list.h"

#include <algorithm>
#include <cstdio>

#include "tcl_util.h"

namespace pvr::tcl {
namespace {

using nlohmann::json;

const VolumeOptionRow kVolumeOptions[] = {
    {"-dataset", "NAME", "the volume's data: a catalog name (see list datasets); required by add"},
    {"-tf", "{S R G B A ...}", "its transfer function's control points, as set -tf"},
    {"-tfpreset", "FILE ?-absolute?", "its transfer function from a ParaView preset, as set -tfpreset"},
    {"-unitdist", "D", "the length its opacities are for, as set -unitdist"},
    {"-visible", "BOOLEAN", "whether it is drawn (an invisible volume stays loaded); default on"},
    {nullptr, nullptr, nullptr}};

// Applies `options` to the volume entry `volume`; errors name `command`.
void applyVolumeOptions(json& volume, const std::vector<VolumeOption>& options, const std::string& command) {
  for (const auto& [option, value, absolute] : options) {
    try {
      if (option == "-dataset") {
        if (value.empty()) argsError("DATASET", "-dataset needs a dataset name (see list datasets)");
        volume["dataset"] = value;
      } else if (option == "-visible") {
        volume["visible"] = parseBoolean(option, value);
      } else if (const auto tf = transferOption(option, value, absolute)) {
        // Merging drops the patch's nulls (the other sources of a transfer
        // function): the list is sent whole and must hold none.
        volume["transfer_function"].merge_patch(*tf);
      } else {
        argsError("OPTION", "bad option \"" + option + "\"");
      }
    } catch (const TclError& e) {
      throw TclError(e.code(), command + ": " + e.what());
    }
  }
}

// The change that sends `list` as the session's volumes. From a session of
// one dataset it also retires the single form: the dataset and top-level
// transfer function now live in the list (the SetScene's empty dataset
// leaves the server's as it is; the list replaces it).
SettingsChange listChange(const Settings& settings, json list, const std::string& command) {
  SettingsChange change;
  change.command = command;
  change.patch["volumes"] = std::move(list);
  if (!settings.scene.contains("volumes")) {
    change.dataset = !settings.dataset.empty();
    change.datasetName.clear();
    if (settings.scene.contains("transfer_function")) change.patch["transfer_function"] = nullptr;
    change.forgotten = transferOptionNames();
    change.forgotten.push_back("-dataset");
  }
  return change;
}

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

std::string volumeNames(const json& list) {
  std::string names;
  for (const auto& v : list) names += (names.empty() ? "" : ", ") + v.value("name", std::string());
  return names.empty() ? "none" : names;
}

}  // namespace

const VolumeOptionRow* volumeOptions() { return kVolumeOptions; }

json volumeList(const Settings& settings) {
  if (const auto list = settings.scene.find("volumes"); list != settings.scene.end() && list->is_array())
    return *list;
  if (settings.dataset.empty()) return json::array();
  json single = {{"name", kSingleVolumeName}, {"dataset", settings.dataset}, {"visible", true}};
  if (settings.scene.contains("transfer_function")) single["transfer_function"] = settings.scene["transfer_function"];
  return json::array({single});
}

const json& findVolume(const json& list, const std::string& name, const std::string& command) {
  for (const auto& v : list)
    if (v.value("name", std::string()) == name) return v;
  argsError("VOLUME", command + ": no volume \"" + name + "\"; the session's volumes are " + volumeNames(list));
}

SettingsChange addVolume(const Settings& settings, const std::string& name, const std::vector<VolumeOption>& options) {
  const std::string command = "volume add " + name;
  if (name.empty() || name[0] == '-')
    argsError("VOLUME", "volume add: a volume needs a name that is not empty and does not start with '-', got \"" +
                            name + "\"");
  json list = volumeList(settings);
  for (const auto& v : list)
    if (v.value("name", std::string()) == name)
      argsError("VOLUME", command + ": the session has a volume named \"" + name + "\" already (volume configure " +
                              name + " changes it)");
  json volume = {{"name", name}, {"visible", true}};
  // A transfer function set before any dataset is the first volume's.
  if (list.empty() && settings.scene.contains("transfer_function"))
    volume["transfer_function"] = settings.scene["transfer_function"];
  applyVolumeOptions(volume, options, command);
  if (!volume.contains("dataset"))
    argsError("DATASET", command + ": -dataset NAME is required (see list datasets)");
  list.push_back(std::move(volume));
  return listChange(settings, std::move(list), command);
}

SettingsChange removeVolume(const Settings& settings, const std::string& name) {
  const std::string command = "volume remove " + name;
  json list = volumeList(settings);
  findVolume(list, name, command);
  if (list.size() == 1)
    argsError("VOLUME", command + ": \"" + name +
                            "\" is the session's only volume; set -dataset NAME shows another in its place");
  list.erase(std::find_if(list.begin(), list.end(), [&](const json& v) { return v.value("name", std::string()) == name; }));
  return listChange(settings, std::move(list), command);
}

SettingsChange configureVolume(const Settings& settings, const std::string& name,
                               const std::vector<VolumeOption>& options) {
  const std::string command = "volume configure " + name;
  json list = volumeList(settings);
  findVolume(list, name, command);
  for (auto& v : list)
    if (v.value("name", std::string()) == name) applyVolumeOptions(v, options, command);
  return listChange(settings, std::move(list), command);
}

std::string transferSummary(const json& tf) {
  if (!tf.is_object() || tf.empty()) return "default";
  std::string text;
  if (const auto points = tf.find("points"); points != tf.end() && points->is_array() && !points->empty()) {
    text = std::to_string(points->size()) + " points";
    const auto scalar = [](const json& p) { return p.is_array() && !p.empty() && p[0].is_number(); };
    if (scalar(points->front()) && scalar(points->back()))
      text += " " + number(points->front()[0].get<double>()) + ".." + number(points->back()[0].get<double>());
  } else if (const auto preset = tf.find("paraview"); preset != tf.end()) {
    const json& first = preset->is_array() && !preset->empty() ? preset->front() : *preset;
    text = "preset " + (first.is_object() && first.contains("Name") && first["Name"].is_string()
                            ? first["Name"].get<std::string>()
                            : std::string("(unnamed)"));
  } else if (const auto file = tf.find("paraview_preset"); file != tf.end() && file->is_string()) {
    text = "preset " + file->get<std::string>();
  } else {
    text = "default";
  }
  if (tf.value("absolute", false)) text += ", absolute";
  if (const auto unit = tf.find("unit_distance"); unit != tf.end() && unit->is_number())
    text += ", unit distance " + number(unit->get<double>());
  return text;
}

std::string volumeOptionsHelp() {
  std::string text;
  for (const VolumeOptionRow* o = kVolumeOptions; o->name; ++o) {
    std::string left = std::string("  ") + o->name + " " + o->value;
    left.resize(std::max<std::size_t>(left.size() + 1, 36), ' ');
    text += left + o->meaning + "\n";
  }
  return text;
}

}  // namespace pvr::tcl
