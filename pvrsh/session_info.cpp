// Session: `:s info`, the loaded dataset as a Tcl dict, from the server's
// status entries (node/status.cpp): dims, spacing, origin, bounds, dtype,
// range and the 256-bin histogram the server counts when it is first asked
// after loading the data. What the GUI's transfer-function editor draws; no file is read here.
#include <utility>

#include "session.h"

namespace pvr::tcl {

Tcl_Obj* Session::infoObj() {
  requireOpen("info");
  const auto entries = serverStatus();
  if (!entries)
    throw TclError({"PVR", "STATE", "BUSY"}, "info: the server answers between sequences; wait for the one in flight");
  // dict key -> status entry it comes from.
  static const std::pair<const char*, const char*> kKeys[] = {
      {"dataset", "dataset"}, {"dims", "dims"},   {"spacing", "spacing"},     {"origin", "origin"},
      {"bounds", "bounds"},   {"dtype", "dtype"}, {"range", "value_range"}, {"histogram", "histogram"},
      {"warning", "warning"}};
  Tcl_Obj* d = Tcl_NewDictObj();
  bool loaded = false;
  for (const auto& [key, entry] : kKeys)
    for (const auto& kv : *entries)
      if (kv.key == entry) {
        Tcl_DictObjPut(nullptr, d, Tcl_NewStringObj(key, -1), Tcl_NewStringObj(kv.value.data(), int(kv.value.size())));
        loaded = loaded || kv.key == "dims";
      }
  if (!loaded) {
    Tcl_DecrRefCount(d);
    throw TclError({"PVR", "STATE", "NODATA"}, "info: no dataset loaded; set -dataset NAME first");
  }
  return d;
}

}  // namespace pvr::tcl
