// The session's volumes (issue 12): what `:s volume add|remove|configure|
// list` work on. The session keeps its volumes in the form the server takes
// (docs/scene.md, `volumes`: entries {"name", "dataset", "visible",
// "transfer_function"}) inside Settings::scene, and each command builds the
// SettingsChange that sends the whole list as one SetScene patch
// {"volumes": [...]} (docs/pvrsh.md, "Several volumes"). A session of one
// dataset (`set -dataset D`) is the one-element list of it, named "volume"
// as the scene document names its single form; the first volume command
// turns it into a list. No Tcl here beyond the errors: session_volumes.cpp
// is the command.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scene_options.h"

namespace pvr::tcl {

// One option of `volume add|configure` as given.
struct VolumeOption {
  std::string option;  // "-tf"
  std::string value;
  bool absolute = false;  // -tfpreset only: "-absolute" followed its value
};

// One row per option of `volume add|configure`. The transfer-function
// options are set's own (transferOption), parsed there.
struct VolumeOptionRow {
  const char* name;  // first field: Tcl_GetIndexFromObjStruct reads it
  const char* value;      // "{S R G B A ...}"
  const char* meaning;    // for help
};
// The rows, ending with a row whose name is nullptr.
const VolumeOptionRow* volumeOptions();

// The name the single form's volume has in the list (docs/scene.md).
inline constexpr const char* kSingleVolumeName = "volume";

// The volumes of `settings` in the server's form: the volume list, or for a
// session of one dataset the one-element list of it; empty when neither.
nlohmann::json volumeList(const Settings& settings);

// The entry of volume `name` in `list`, or TclError {PVR ARGS VOLUME}
// naming `command` and the volumes there are.
const nlohmann::json& findVolume(const nlohmann::json& list, const std::string& name, const std::string& command);

// The changes the commands make: each checks everything first (unknown or
// duplicate names, bad options, a missing -dataset) and throws TclError
// {PVR ARGS ...} naming the command, the volume and the option; nothing is
// changed then. The change sends the whole list.
SettingsChange addVolume(const Settings& settings, const std::string& name, const std::vector<VolumeOption>& options);
SettingsChange removeVolume(const Settings& settings, const std::string& name);
SettingsChange configureVolume(const Settings& settings, const std::string& name,
                               const std::vector<VolumeOption>& options);

// One line about a transfer function object for `volume list`: "default",
// "3 points 0..200", "preset Cool to Warm", "preset bone.json", with
// ", absolute" and ", unit distance D" when set.
std::string transferSummary(const nlohmann::json& tf);

// `:s help volume`'s list of options with their value forms.
std::string volumeOptionsHelp();

}  // namespace pvr::tcl
