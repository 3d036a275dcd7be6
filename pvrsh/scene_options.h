// The options of `:s set`: each maps to a piece of a SetScene document
// (docs/scene.md and the "runtime" object of docs/runtime.md, sent as an
// RFC 7386 merge patch) or to the cluster layout (SetLayout). One table row
// per option in scene_options.cpp.
#pragma once

#include <tcl.h>

#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pvr_protocol.h"

namespace pvr::tcl {

// What the user has set so far; sent whole when a session opens.
struct Settings {
  std::string dataset;                          // catalog name; empty: none yet
  nlohmann::json scene = nlohmann::json::object();  // every scene key set so far, merged
  std::vector<proto::ClusterSpec> clusters;     // desired layout; empty: the master's default
  std::vector<std::pair<std::string, std::string>> shown;  // option -> value as given, first-set order
  // Camera moves (-zoom, -pan, ...) not sent yet: they change the camera in
  // force once, so they are sent once (by open, before it) and not kept.
  nlohmann::json cameraMoves = nlohmann::json::array();
};

// What one `set` call changed, to be sent to an open session.
struct SettingsChange {
  bool dataset = false;                              // -dataset given
  std::string datasetName;                           // its value
  nlohmann::json patch = nlohmann::json::object();   // merge patch of the scene keys given
  bool layout = false;                               // -cluster or -group given
  std::vector<std::pair<std::string, std::string>> shown;  // option -> value as given, in order
  // Options no longer shown by `set OPTION` (their values moved into the
  // volume list: `volume add` on a session of one dataset).
  std::vector<std::string> forgotten;
  // What a refusal names: empty for `set` (its options as given are named),
  // else the command ("volume add pet").
  std::string command;
};

// Applies what `change` sent to `settings`: the dataset, the scene keys
// (camera moves apart: they are not kept) and the values shown. The
// session keeps what the server accepted this way, one acknowledged
// SetScene at a time (issue 14, point 6).
void applyChange(Settings& settings, const SettingsChange& change);
// Everything `settings` holds as one change: what `open` sends.
SettingsChange wholeChange(const Settings& settings);

// The names the server accepts, by status key (`strategies`,
// `decompositions`; docs/protocol.md, StatusReply); nullopt when no server
// can say now (no session open, a render in flight, an older server). pvrsh
// keeps no list of its own: a name the server does not know is then refused
// by the server.
using ServerNames = std::function<std::optional<std::vector<std::string>>(std::string_view statusKey)>;

// Applies `set` options (name value pairs) to `settings`. All options are
// checked before any is applied, so a bad one changes nothing. Throws
// TclError {PVR ARGS OPTION} with a message naming the option and value, and
// the standard "bad option" message for an unknown option.
SettingsChange applyOptions(Tcl_Interp* interp, Settings& settings, int objc, Tcl_Obj* const objv[],
                            const ServerNames& serverNames);

// The transfer-function options of `set` (-tf, -tfpreset with its
// -absolute flag, -unitdist) as the "transfer_function" merge patch they
// make, for `volume add|configure` (volume_list.h): set's parsing and
// errors, in one place. nullopt when `option` is none of them.
std::optional<nlohmann::json> transferOption(const std::string& option, const std::string& value, bool absolute);
// Those options' names: {"-tf", "-tfpreset", "-unitdist"}.
const std::vector<std::string>& transferOptionNames();

// The value last given for `option` (e.g. "-imagesz"), or an error naming
// the known options.
std::string shownOption(Tcl_Interp* interp, const Settings& settings, Tcl_Obj* option);

// The image size the server renders for `settings`: -imagesz as set, else
// its default (the option table's, which is the server's).
std::pair<int, int> imageSize(const Settings& settings);

// `:s set` with no argument: every option as {option value default}, in
// table order, one per line; value is "" for an option never given.
Tcl_Obj* optionListing(const Settings& settings);
// Every option with the form of its value and its default, one per line,
// for `:s help set`.
std::string optionsHelp();
// A Tcl list of `rows`, one element per line.
Tcl_Obj* linedList(const std::vector<Tcl_Obj*>& rows);
// The scene patch `open` sends: every key set so far and the camera moves
// not sent yet ("camera_moves", docs/scene.md).
nlohmann::json openingScene(const Settings& settings);

// A cluster layout as a Tcl list of {role ranks group} triples.
Tcl_Obj* layoutObj(const std::vector<proto::ClusterSpec>& clusters);

}  // namespace pvr::tcl
