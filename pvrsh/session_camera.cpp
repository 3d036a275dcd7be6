// Session: `camera`, the camera in force as the server reports it in its
// status entries (camera_*, docs/runtime.md): the automatic camera it
// placed for the dataset, or the one the scene sets.
#include "session.h"

namespace pvr::tcl {

Tcl_Obj* Session::cameraObj() {
  requireOpen("camera");
  const auto entries = serverStatus();
  if (!entries)
    throw TclError({"PVR", "STATE", "BUSY"}, "camera: a sequence is in flight; ask again when it is done (wait)");
  // Status key -> dict key, in the order shown.
  static const std::pair<const char*, const char*> kKeys[] = {
      {"camera_automatic", "automatic"}, {"camera_projection", "projection"}, {"camera_eye", "eye"},
      {"camera_look_at", "look_at"},     {"camera_up", "up"},                 {"camera_fov_y_deg", "fov_y_deg"},
      {"camera_height", "height"}};
  Tcl_Obj* d = Tcl_NewDictObj();
  for (const auto& [statusKey, key] : kKeys)
    for (const auto& kv : *entries)
      if (kv.key == statusKey)
        Tcl_DictObjPut(nullptr, d, Tcl_NewStringObj(key, -1), Tcl_NewStringObj(kv.value.c_str(), int(kv.value.size())));
  int size = 0;
  Tcl_DictObjSize(nullptr, d, &size);
  if (size == 0) {
    Tcl_DecrRefCount(d);
    throw TclError({"PVR", "STATE", "NODATASET"},
                   "camera: the server has no camera yet: it places one when a dataset is loaded (set -dataset)");
  }
  return d;
}

}  // namespace pvr::tcl
