// Session: `list status` (the session's own state and the server's status
// entries) and the names the server offers for runtime settings.
#include "session.h"

namespace pvr::tcl {

std::optional<std::vector<proto::KeyValue>> Session::serverStatus() {
  // With a sequence in flight the master answers only between waves, so
  // the answer could wait for a whole frame: not asked then.
  if (state_ != State::kOpen || !book_.sequences.empty()) return std::nullopt;
  std::vector<proto::KeyValue> entries;
  for (const auto& m : query(proto::StatusRequest{}, 30))
    if (const auto* r = std::get_if<proto::StatusReply>(&m)) entries.insert(entries.end(), r->entries.begin(), r->entries.end());
  return entries;
}

std::optional<std::vector<std::string>> Session::serverNames(std::string_view key) {
  std::optional<std::vector<proto::KeyValue>> entries;
  try {
    entries = serverStatus();
  } catch (const TclError&) {
    return std::nullopt;  // the request that follows meets the same trouble and reports it
  }
  if (!entries) return std::nullopt;
  for (const auto& kv : *entries) {
    if (kv.key != key) continue;
    int count = 0;
    const char** items = nullptr;
    if (Tcl_SplitList(nullptr, kv.value.c_str(), &count, &items) != TCL_OK) return std::nullopt;
    std::vector<std::string> names(items, items + count);
    Tcl_Free(reinterpret_cast<char*>(items));
    return names;
  }
  return std::nullopt;
}

Tcl_Obj* Session::statusObj() {
  static const char* const kStates[] = {"closed", "connecting", "open", "failed"};
  const auto entries = serverStatus();  // first: it may throw, and runs the event loop
  Tcl_Obj* d = Tcl_NewDictObj();
  const auto put = [&](const char* k, Tcl_Obj* v) { Tcl_DictObjPut(nullptr, d, Tcl_NewStringObj(k, -1), v); };
  const auto str = [](const std::string& s) { return Tcl_NewStringObj(s.data(), int(s.size())); };
  put("session", str(name_));
  put("state", Tcl_NewStringObj(kStates[int(state_)], -1));
  put("server", str(peer_));
  put("software", str(serverSoftware_));
  put("max_ranks", Tcl_NewWideIntObj(maxRanks_));
  put("ranks", Tcl_NewWideIntObj(ranks_));
  put("layout", layoutObj(state_ == State::kOpen ? layout_ : settings_.clusters));
  put("dataset", str(settings_.dataset));
  Tcl_Obj* options = Tcl_NewDictObj();
  for (const auto& [k, v] : settings_.shown) Tcl_DictObjPut(nullptr, options, str(k), str(v));
  put("options", options);
  put("scene", str(settings_.scene.dump()));
  put("window", str(photo_));
  put("callback", callback_ ? callback_ : Tcl_NewObj());
  put("file", str(files_.pattern()));
  put("fps", Tcl_NewIntObj(animationFps_));
  put("dir", str(dir_));
  put("frames_received", Tcl_NewWideIntObj(Tcl_WideInt(framesReceived_)));
  put("busy", Tcl_NewBooleanObj(!book_.sequences.empty()));
  Tcl_Obj* seq = Tcl_NewDictObj();
  const Sequence& latest = book_.latest();
  Tcl_DictObjPut(nullptr, seq, Tcl_NewStringObj("request", -1), str(latest.label));
  Tcl_DictObjPut(nullptr, seq, Tcl_NewStringObj("done", -1), Tcl_NewWideIntObj(Tcl_WideInt(latest.frames.size())));
  Tcl_DictObjPut(nullptr, seq, Tcl_NewStringObj("total", -1), Tcl_NewWideIntObj(latest.total));
  put("sequence", seq);
  Tcl_Obj* remote = Tcl_NewDictObj();
  if (entries)
    for (const auto& kv : *entries) Tcl_DictObjPut(nullptr, remote, str(kv.key), str(kv.value));
  put("remote", remote);
  return d;
}

}  // namespace pvr::tcl
