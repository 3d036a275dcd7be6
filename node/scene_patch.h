// The session's scene as the master keeps it: the scene document and the
// "runtime" object of SetScene (docs/runtime.md), each the merge (RFC 7396)
// of every patch the master accepted. A patch is checked as a whole before
// it is kept, whether or not a dataset is open: the merged document must
// parse as a scene (core::parseScene, with a stand-in volume while none is
// named), the merged runtime object must give settings (settingsFrom), and
// the image must fit one frame in the session's pixel format
// (proto::checkImageSize). A refused patch changes nothing.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <variant>

#include "pvr_protocol.h"
#include "runtime_settings.h"

namespace pvr::node {

// The folder of the data directory that holds the server's ParaView
// presets: a scene's "paraview_preset" names a file in it (docs/runtime.md).
inline constexpr const char* kPresetFolder = "presets";

struct SessionScene {
  nlohmann::json doc = nlohmann::json::object();      // without "runtime"
  nlohmann::json runtime = nlohmann::json::object();  // the merged "runtime" object
  RuntimeSettings settings;                           // what `runtime` gives
  // A dataset is named (or a procedural volume given): the ranks can load it.
  bool hasVolume() const { return doc.contains("volume") || doc.contains("volumes"); }
};

// `current` with `request` applied and checked, or the error that refuses
// it. The dataset name resolves inside `dataDir` (a real path), to the
// volume file the ranks open; a "volume" with a "file" in the JSON is
// refused (null, which removes it, is not), so files come only through
// dataset names; a "paraview_preset"
// resolves inside dataDir/presets. Every name resolves to a regular file
// inside its folder after symlinks, or is refused in the same words
// whether it exists or not. "volumes" is patched as docs/protocol.md
// (SetScene) says: a list replaces the volumes, an object patches them by
// name; their entries name data by "dataset", resolved likewise.
std::variant<SessionScene, proto::ProtocolError> patchScene(const SessionScene& current,
                                                            const proto::SetScene& request,
                                                            const std::string& dataDir);

}  // namespace pvr::node
