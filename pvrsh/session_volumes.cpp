// `:s volume ACTION ...`: the session's volumes (docs/pvrsh.md, "Several
// volumes"). Each action is one row of kActions; the list and the changes
// are volume_list.cpp's, and a change goes out as `set`'s do (one SetScene,
// its refusal reported and undone as set's, session_settled.cpp).
#include "session_volumes.h"

#include <string_view>
#include <vector>

#include "session.h"
#include "volume_list.h"

namespace pvr::tcl {
namespace {

using nlohmann::json;

std::string str(Tcl_Obj* o) { return Tcl_GetString(o); }
Tcl_Obj* text(const std::string& v) { return Tcl_NewStringObj(v.data(), int(v.size())); }

// One volume entry as the Tcl dict `volume list` gives: name, dataset,
// visible (0 or 1), tf (transferSummary), points (the control points as
// -tf takes them, flat; empty when the transfer function is not points).
Tcl_Obj* volumeDict(const json& volume) {
  Tcl_Obj* d = Tcl_NewDictObj();
  const auto put = [&](const char* k, Tcl_Obj* v) { Tcl_DictObjPut(nullptr, d, Tcl_NewStringObj(k, -1), v); };
  const json tf = volume.value("transfer_function", json::object());
  Tcl_Obj* points = Tcl_NewListObj(0, nullptr);
  if (tf.contains("points") && tf["points"].is_array())
    for (const auto& point : tf["points"])
      for (const auto& v : point)
        if (v.is_number()) Tcl_ListObjAppendElement(nullptr, points, Tcl_NewDoubleObj(v.get<double>()));
  put("name", text(volume.value("name", std::string())));
  put("dataset", text(volume.value("dataset", std::string())));
  put("visible", Tcl_NewBooleanObj(volume.value("visible", true)));
  put("tf", text(transferSummary(tf)));
  put("points", points);
  return d;
}

// The options objv[first..] of add or configure; errors name `command`.
std::vector<VolumeOption> parseOptions(Tcl_Interp* interp, int objc, Tcl_Obj* const objv[], int first,
                                       const std::string& command) {
  std::vector<VolumeOption> options;
  for (int i = first; i < objc; i += 2) {
    int index = 0;
    if (Tcl_GetIndexFromObjStruct(interp, objv[i], volumeOptions(), sizeof(VolumeOptionRow), "option", 0, &index) !=
        TCL_OK)
      throw TclError({"PVR", "ARGS", "OPTION"}, command + ": " + Tcl_GetStringResult(interp));
    const std::string option = volumeOptions()[index].name;
    if (i + 1 >= objc) argsError("VALUE", command + ": value for \"" + option + "\" missing");
    // "-tfpreset FILE -absolute": the flag set's -tfpreset takes.
    const bool absolute = option == "-tfpreset" && i + 2 < objc && str(objv[i + 2]) == "-absolute";
    options.push_back({option, str(objv[i + 1]), absolute});
    if (absolute) ++i;
  }
  return options;
}

// Keeps `change` in the session's settings and sends it when open.
void apply(Session& s, const SettingsChange& change) {
  applyChange(s.settings_, change);
  s.applySettings(change);
}

using Action = int (*)(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]);

// :s volume add NAME -dataset D ?option value ...?
int addAction(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  if (objc < 4) {
    Tcl_WrongNumArgs(interp, 3, objv, "name -dataset name ?option value ...?");
    return TCL_ERROR;
  }
  const std::string name = str(objv[3]);
  apply(s, addVolume(s.settings_, name, parseOptions(interp, objc, objv, 4, "volume add " + name)));
  Tcl_ResetResult(interp);
  return TCL_OK;
}

// :s volume configure NAME ?option value ...?  (no option: the volume's dict)
int configureAction(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  if (objc < 4) {
    Tcl_WrongNumArgs(interp, 3, objv, "name ?option value ...?");
    return TCL_ERROR;
  }
  const std::string name = str(objv[3]), command = "volume configure " + name;
  if (objc == 4) {
    s.settle(30);
    Tcl_SetObjResult(interp, volumeDict(findVolume(volumeList(s.settings_), name, command)));
    return TCL_OK;
  }
  apply(s, configureVolume(s.settings_, name, parseOptions(interp, objc, objv, 4, command)));
  Tcl_ResetResult(interp);
  return TCL_OK;
}

// :s volume list: one dict per volume, one per line.
int listAction(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  if (objc != 3) {
    Tcl_WrongNumArgs(interp, 3, objv, nullptr);
    return TCL_ERROR;
  }
  // What is listed is what the server accepted, as for `set`.
  s.settle(30);
  std::vector<Tcl_Obj*> rows;
  for (const auto& v : volumeList(s.settings_)) rows.push_back(volumeDict(v));
  Tcl_SetObjResult(interp, linedList(rows));
  return TCL_OK;
}

// :s volume remove NAME
int removeAction(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  if (objc != 4) {
    Tcl_WrongNumArgs(interp, 3, objv, "name");
    return TCL_ERROR;
  }
  apply(s, removeVolume(s.settings_, str(objv[3])));
  Tcl_ResetResult(interp);
  return TCL_OK;
}

struct ActionRow {
  const char* name;  // first field: Tcl_GetIndexFromObjStruct reads it
  Action action;
  const char* usage;
  const char* summary;
};

const ActionRow kActions[] = {
    {"add", addAction, "name -dataset name ?option value ...?",
     "add a volume with its own data and transfer function to the scene"},
    {"configure", configureAction, "name ?option value ...?",
     "change a volume's options (no option: the volume as a dict, as list gives it)"},
    {"list", listAction, "", "the volumes, one dict {name dataset visible tf points} per line"},
    {"remove", removeAction, "name", "take a volume out of the scene (the last one stays)"},
    {nullptr, nullptr, nullptr, nullptr}};

}  // namespace

int volumeCmd(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  if (objc < 3) {
    Tcl_WrongNumArgs(interp, 2, objv, "add|configure|list|remove ?arg ...?");
    return TCL_ERROR;
  }
  int index = 0;
  if (Tcl_GetIndexFromObjStruct(interp, objv[2], kActions, sizeof(ActionRow), "volume action", 0, &index) != TCL_OK)
    throw TclError({"PVR", "ARGS", "VOLUME"}, Tcl_GetStringResult(interp));
  return kActions[index].action(s, interp, objc, objv);
}

std::string volumeHelp(const std::string& object) {
  std::string text;
  for (const ActionRow* a = kActions; a->name; ++a) {
    text.append(object).append(" volume ").append(a->name);
    if (*a->usage) text.append(" ").append(a->usage);
    text.append("\n    ").append(a->summary).append("\n");
  }
  return text + "options of add and configure:\n" + volumeOptionsHelp();
}

}  // namespace pvr::tcl
