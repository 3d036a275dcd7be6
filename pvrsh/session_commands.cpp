// The subcommands of a session object (paper 003, Table 1), one handler per
// row of kSubcommands. Handlers throw TclError; objCmd turns it into the
// interpreter's result and -errorcode.
#include <tk.h>

#include <cctype>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "session.h"
#include "session_help.h"
#include "session_volumes.h"

namespace pvr::tcl {
namespace {

using Handler = int (*)(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]);

// One row per subcommand. `usage` is the argument list that wrong # args
// and `help` print; `summary` is help's line about it. A row without them
// is a bug that tests/pvrsh/help.test catches.
struct Subcommand {
  const char* name;  // first field: Tcl_GetIndexFromObjStruct reads it
  Handler handler;
  const char* usage = nullptr;    // "host?:port? ?-ranks n? ..."; "" for none
  const char* summary = nullptr;  // one line
};

// The usage of objv[1]'s row (defined after the table), for
// Tcl_WrongNumArgs(interp, 2, objv, usageOf(objv)).
const char* usageOf(Tcl_Obj* const objv[]);

std::string str(Tcl_Obj* o) { return Tcl_GetString(o); }

// Splits HOST[:PORT]; the port defaults to kDefaultPort.
constexpr int kDefaultPort = 7350;
void splitHostPort(const std::string& address, std::string& host, int& port) {
  const auto colon = address.rfind(':');
  port = kDefaultPort;
  host = address;
  if (colon != std::string::npos && address.find(':') == colon) {
    host = address.substr(0, colon);
    port = int(parseInteger("-port", address.substr(colon + 1), 1, 65535));
  }
  if (host.empty()) argsError("HOST", "open: no host in '" + address + "'");
}

// A batch-system account: one word of printable characters. What accounts
// exist is the batch system's to judge (pvrd passes it to Slurm).
std::string accountName(const std::string& v) {
  if (v.empty()) argsError("ACCOUNT", "-account needs an account name (leave the option out for the site's default)");
  for (unsigned char c : v)
    if (!std::isgraph(c) && c < 0x80)
      argsError("ACCOUNT", "-account '" + v + "' is not one word: an account name has no spaces or control characters");
  return v;
}

// :s open HOST[:PORT] ?-ranks N? ?-account A? ?-token-file F? ?-timeout S?
int openCmd(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  if (objc < 3 || objc % 2 == 0) {
    Tcl_WrongNumArgs(interp, 2, objv, usageOf(objv));
    return TCL_ERROR;
  }
  static const char* const kOptions[] = {"-account", "-ranks", "-timeout", "-token-file", nullptr};
  OpenRequest request;
  request.ranks = s.ranksWanted_;
  if (const char* env = std::getenv("PVR_TOKEN_FILE")) request.tokenFile = env;
  for (int i = 3; i < objc; i += 2) {
    int index = 0;
    if (Tcl_GetIndexFromObj(interp, objv[i], kOptions, "option", 0, &index) != TCL_OK)
      throw TclError({"PVR", "ARGS", "OPTION"}, Tcl_GetStringResult(interp));
    const std::string v = str(objv[i + 1]);
    if (index == 0) request.account = accountName(v);
    if (index == 1) request.ranks = std::uint32_t(parseInteger("-ranks", v, 1, 1 << 20));
    if (index == 2) request.timeout = parseNumbers("-timeout", v, 1)[0];
    if (index == 3) request.tokenFile = v;
  }
  if (!(request.timeout > 0)) argsError("TIMEOUT", "-timeout must be > 0 seconds");
  splitHostPort(str(objv[2]), request.host, request.port);
  s.ranksWanted_ = request.ranks;
  s.open(request);
  return TCL_OK;
}

int closeCmd(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  if (objc != 2) {
    Tcl_WrongNumArgs(interp, 2, objv, usageOf(objv));
    return TCL_ERROR;
  }
  s.close("pvrsh: session closed");
  return TCL_OK;
}

// :s image window|callback|file|dir ?VALUE?  (no value: the current one);
// :s image file movie.gif|movie.mp4 -fps N  (the animation's frame rate)
int imageCmd(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  static const char* const kKinds[] = {"callback", "dir", "file", "window", nullptr};
  if (objc != 3 && objc != 4 && objc != 6) {
    Tcl_WrongNumArgs(interp, 2, objv, usageOf(objv));
    return TCL_ERROR;
  }
  int kind = 0;
  if (Tcl_GetIndexFromObj(interp, objv[2], kKinds, "image target", 0, &kind) != TCL_OK)
    throw TclError({"PVR", "ARGS", "IMAGE"}, Tcl_GetStringResult(interp));
  // The frame rate belongs to the animated file, so it is set with it and
  // every `image file` without -fps goes back to the default; it is no
  // `set` option because those are the server's scene, this is pvrsh's.
  int fps = kDefaultFps;
  if (objc == 6) {
    if (kind != 2 || str(objv[4]) != "-fps")
      throw TclError({"PVR", "ARGS", "IMAGE"}, "image: only \"image file FILE -fps N\" takes an option, got \"" +
                                                   str(objv[4]) + "\" after " + str(objv[2]));
    fps = fpsOf(str(objv[5]));
  }
  if (objc == 3) {
    const std::string values[] = {"", s.dir_, s.animatedTarget_.empty() ? s.files_.pattern() : s.animatedTarget_,
                                  s.photo_};
    Tcl_SetObjResult(interp, kind == 0 ? (s.callback_ ? s.callback_ : Tcl_NewObj()) : Tcl_NewStringObj(values[kind].c_str(), -1));
    return TCL_OK;
  }
  const std::string v = str(objv[3]);
  switch (kind) {
    case 0:
      if (s.callback_) Tcl_DecrRefCount(s.callback_);
      s.callback_ = nullptr;
      if (!v.empty()) {
        s.callback_ = objv[3];
        Tcl_IncrRefCount(s.callback_);
      }
      break;
    case 1:
      if (!v.empty()) {
        numberedInDirectory(v, s.name_);  // refuses names the file system would cut
        Tcl_Obj* path = objv[3];
        if (Tcl_FSCreateDirectory(path) != TCL_OK && Tcl_FSAccess(path, 2) != 0)
          throw TclError({"PVR", "IO"}, "image dir: cannot create or write " + v);
      }
      s.dir_ = v;
      break;
    case 2:
      if (v.empty()) {
        if (objc == 6) throw TclError({"PVR", "ARGS", "FPS"}, "image file: -fps needs a .gif or .mp4 file, got none");
        s.files_ = {};
        s.animatedTarget_.clear();
      } else {
        std::string animated;
        NumberedFile files = numberedFileOf(v, animated);
        if (objc == 6 && animated.empty())
          throw TclError({"PVR", "ARGS", "FPS"},
                         "image file: -fps is the frame rate of a .gif or .mp4 file; '" + v + "' writes PNG frames only");
        s.files_ = files;
        s.animatedTarget_ = animated;
      }
      s.animationFps_ = fps;
      break;
    case 3:
      if (!v.empty()) {
        if (!tkAvailable(interp))
          throw TclError({"PVR", "IMAGE", "NOTK"}, "image window needs Tk: package require Tk first (or run pvrsh with a display)");
        if (!Tk_FindPhoto(interp, v.c_str()))
          throw TclError({"PVR", "IMAGE", "NOPHOTO"}, "image \"" + v + "\" is not a photo image");
      }
      s.photo_ = v;
      break;
  }
  return TCL_OK;
}

// :s info: the loaded dataset's dims, spacing, origin, bounds, dtype, range, histogram.
int infoCmd(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  if (objc != 2) {
    Tcl_WrongNumArgs(interp, 2, objv, "");
    return TCL_ERROR;
  }
  Tcl_SetObjResult(interp, s.infoObj());
  return TCL_OK;
}

// :s list status | :s list datasets ?-steps|-details?
// Datasets: the catalog's names (stems); with -steps a dictionary of name
// -> number of time steps (1 for a single volume), with -details name ->
// dict {file format dims dtype steps note}, in catalog order.
int listCmd(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  static const char* const kWhat[] = {"datasets", "status", nullptr};
  if (objc != 3 && objc != 4) {
    Tcl_WrongNumArgs(interp, 2, objv, usageOf(objv));
    return TCL_ERROR;
  }
  int what = 0;
  if (Tcl_GetIndexFromObj(interp, objv[2], kWhat, "list", 0, &what) != TCL_OK)
    throw TclError({"PVR", "ARGS", "LIST"}, Tcl_GetStringResult(interp));
  const std::string flag = objc == 4 ? str(objv[3]) : "";
  if (objc == 4 && (what == 1 || (flag != "-steps" && flag != "-details")))
    argsError("LIST", "bad option \"" + flag + "\": " +
                          (what == 1 ? "list status takes no option" : "list datasets takes -steps or -details"));
  if (what == 1) {
    Tcl_SetObjResult(interp, s.statusObj());
    return TCL_OK;
  }
  s.requireOpen("list datasets");
  Tcl_Obj* list = Tcl_NewListObj(0, nullptr);
  const auto text = [](const std::string& v) { return Tcl_NewStringObj(v.data(), int(v.size())); };
  for (const auto& m : s.query(proto::CatalogRequest{}, 30))
    if (const auto* c = std::get_if<proto::CatalogReply>(&m))
      for (const auto& entry : c->datasets) {
        Tcl_ListObjAppendElement(nullptr, list, text(entry.name));
        if (flag == "-steps") Tcl_ListObjAppendElement(nullptr, list, Tcl_NewWideIntObj(Tcl_WideInt(entry.steps)));
        if (flag != "-details") continue;
        Tcl_Obj* d = Tcl_NewDictObj();
        Tcl_Obj* dims[3] = {Tcl_NewWideIntObj(entry.dims[0]), Tcl_NewWideIntObj(entry.dims[1]),
                            Tcl_NewWideIntObj(entry.dims[2])};
        const std::pair<const char*, Tcl_Obj*> items[] = {
            {"file", text(entry.file)},     {"format", text(entry.format)},
            {"dims", Tcl_NewListObj(3, dims)}, {"dtype", text(entry.dtype)},
            {"steps", Tcl_NewWideIntObj(Tcl_WideInt(entry.steps))}, {"note", text(entry.note)}};
        for (const auto& [k, v] : items) Tcl_DictObjPut(nullptr, d, Tcl_NewStringObj(k, -1), v);
        Tcl_ListObjAppendElement(nullptr, list, d);
      }
  Tcl_SetObjResult(interp, list);
  return TCL_OK;
}

// :s set OPTION VALUE ?OPTION VALUE ...?  |  :s set OPTION (its value)  |
// :s set (every option: {option value default}, one per line)
int setCmd(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  // What is shown is what the server accepted: its answers to the sets
  // sent are waited for first (a refused value is then gone).
  if (objc == 2) {
    s.settle(30);
    Tcl_SetObjResult(interp, optionListing(s.settings_));
    return TCL_OK;
  }
  if (objc == 3) {
    s.settle(30);
    Tcl_SetObjResult(interp, Tcl_NewStringObj(shownOption(interp, s.settings_, objv[2]).c_str(), -1));
    return TCL_OK;
  }
  // Figure 5 writes "-imagesz 512,512"; "-imagesz 512, 512" (two words) is
  // the same request, so a value ending in a comma takes the next word too.
  std::vector<Tcl_Obj*> words;
  for (int i = 2; i < objc; ++i) {
    const std::string w = str(objv[i]);
    if (!words.empty() && i > 3 && str(words.back()).back() == ',' && w[0] != '-') {
      Tcl_Obj* joined = Tcl_NewStringObj((str(words.back()) + w).c_str(), -1);
      words.back() = joined;
      continue;
    }
    words.push_back(objv[i]);
  }
  for (Tcl_Obj* o : words) Tcl_IncrRefCount(o);
  try {
    // An odd count is checked there: "-tfpreset FILE -absolute" has a flag.
    s.applySettings(applyOptions(interp, s.settings_, int(words.size()), words.data(),
                                 [&s](std::string_view key) { return s.serverNames(key); }));
  } catch (...) {
    for (Tcl_Obj* o : words) Tcl_DecrRefCount(o);
    throw;
  }
  for (Tcl_Obj* o : words) Tcl_DecrRefCount(o);
  Tcl_ResetResult(interp);
  return TCL_OK;
}

// The rules of a rotation request are the protocol's (contract C6): its
// decoders enforce them, and pvrsh asks the same check before sending so
// that a bad request is an error of the command that made it.
void checkRotation(const proto::RenderRotation& r) {
  if (const auto error = r.check(proto::Limits{})) argsError("ROTATION", "render rotate: " + error->text);
}

// S,E?:STRIDE? as a time request: steps S to E (default: the dataset's
// last step, asked of the server's status) every STRIDE-th (default 1).
// The protocol's check applies before sending; whether the steps exist is
// the server's to say.
proto::RenderTimeSteps parseTimeRange(Session& s, const std::string& range) {
  const auto colon = range.find(':');
  const std::string steps = range.substr(0, colon);
  const auto comma = steps.find(',');
  proto::RenderTimeSteps t;
  t.first = std::uint32_t(parseInteger("-first", steps.substr(0, comma), 0, INT32_MAX));
  if (comma != std::string::npos && comma + 1 < steps.size()) {
    t.last = std::uint32_t(parseInteger("-last", steps.substr(comma + 1), 0, INT32_MAX));
  } else {
    // The server's status says how many steps the dataset has.
    s.requireOpen("render time");
    const auto count = s.serverNames("timesteps");
    if (!count || count->size() != 1)
      argsError("TIME", "render time " + range +
                            ": the server cannot say its last step now (no dataset, or a render in flight): give S,E");
    t.last = std::uint32_t(std::max<std::int64_t>(0, parseInteger("timesteps", count->front(), 1, INT32_MAX) - 1));
  }
  if (colon != std::string::npos) t.stride = std::uint32_t(parseInteger("-stride", range.substr(colon + 1), 1, INT32_MAX));
  if (const auto error = t.check(proto::Limits{})) argsError("TIME", "render time " + range + ": " + error->text);
  return t;
}

// :s render steps N ?-every K?: the session's computation volume advances
// N steps, a frame every K-th step and one of the last (docs/steering.md).
// The protocol's check applies before sending; whether the volume is a
// computation is the server's to say.
int renderSteps(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  if (objc != 4 && objc != 6) {
    Tcl_WrongNumArgs(interp, 3, objv, "n ?-every k?");
    return TCL_ERROR;
  }
  proto::RenderSteps r;
  std::string label = "steps " + str(objv[3]);
  r.steps = std::uint32_t(parseInteger("-steps", str(objv[3]), 1, UINT32_MAX));
  if (objc == 6) {
    if (str(objv[4]) != "-every") argsError("STEPS", "render steps: expected -every K, got '" + str(objv[4]) + "'");
    r.every = std::uint32_t(parseInteger("-every", str(objv[5]), 1, UINT32_MAX));
    label += " -every " + str(objv[5]);
  }
  if (const auto error = r.check(proto::Limits{})) argsError("STEPS", "render steps: " + error->text);
  s.render(r, r.frameCount(), label);
  Tcl_SetObjResult(interp, Tcl_NewWideIntObj(r.frameCount()));
  return TCL_OK;
}

// The options after `render frame` and `render rotate AXIS K,K:N`:
// ?-interactive? ?-reduction R?. The reduction of the coarse frame when
// the render is interactive (default 4), else nothing; `wrong` set for a
// word that is neither.
std::optional<std::uint32_t> parseInteractive(int objc, Tcl_Obj* const objv[], int first, bool& wrong) {
  wrong = false;
  bool interactive = false;
  std::uint32_t reduction = 4;
  for (int i = first; i < objc; ++i) {
    const std::string option = str(objv[i]);
    if (option == "-interactive") {
      interactive = true;
    } else if (option == "-reduction" && i + 1 < objc) {
      reduction = std::uint32_t(parseInteger("-reduction", str(objv[++i]), 2, proto::kMaxInteractiveReduction));
      interactive = true;
    } else {
      wrong = true;
      return std::nullopt;
    }
  }
  if (!interactive) return std::nullopt;
  return reduction;
}

// :s render rotate|rotation X,Y,Z S,E:N ?-interactive? ?-reduction R?  |  :s render time S,E?:STRIDE?  |
// :s render frame ?-interactive? ?-reduction R?  |  :s render steps N ?-every K?
int renderCmd(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  static const char* const kKinds[] = {"frame", "rotate", "rotation", "time", "steps", nullptr};
  if (objc < 3) {
    Tcl_WrongNumArgs(interp, 2, objv, usageOf(objv));
    return TCL_ERROR;
  }
  int kind = 0;
  if (Tcl_GetIndexFromObj(interp, objv[2], kKinds, "render", 0, &kind) != TCL_OK)
    throw TclError({"PVR", "ARGS", "RENDER"}, Tcl_GetStringResult(interp));
  if (kind == 4) return renderSteps(s, interp, objc, objv);
  if (kind == 3) {
    if (objc != 4) {
      Tcl_WrongNumArgs(interp, 3, objv, "start,end?:stride?");
      return TCL_ERROR;
    }
    const std::string range = str(objv[3]);
    const proto::RenderTimeSteps t = parseTimeRange(s, range);
    s.render(t, t.frameCount(), "time " + range);
    Tcl_SetObjResult(interp, Tcl_NewWideIntObj(t.frameCount()));
    return TCL_OK;
  }
  if (kind == 0) {
    // An interactive frame: the coarse frame, then the full one.
    bool wrong = false;
    const auto reduction = parseInteractive(objc, objv, 3, wrong);
    if (wrong) {
      Tcl_WrongNumArgs(interp, 3, objv, "?-interactive? ?-reduction R?");
      return TCL_ERROR;
    }
    if (reduction) {
      s.render(proto::RenderInteractive{*reduction, {0, 0, 1}, 0, 1}, 2, "frame -interactive");
      Tcl_SetObjResult(interp, Tcl_NewIntObj(2));
      return TCL_OK;
    }
    s.render(proto::RenderFrame{}, 1, "frame");
    Tcl_SetObjResult(interp, Tcl_NewIntObj(1));
    return TCL_OK;
  }
  bool wrong = false;
  const auto reduction = objc < 5 ? std::nullopt : parseInteractive(objc, objv, 5, wrong);
  if (objc < 5 || wrong) {
    Tcl_WrongNumArgs(interp, 3, objv, "axis start,end:steps ?-interactive? ?-reduction R?");
    return TCL_ERROR;
  }
  const std::string axisText = str(objv[3]), range = str(objv[4]);
  proto::RenderRotation r;
  const auto axis = parseNumbers("-axis", axisText, 3);
  r.axis = {axis[0], axis[1], axis[2]};
  // S,E:N: steps S to E of a full turn of N steps.
  const auto colon = range.find(':'), comma = range.find(',');
  if (colon == std::string::npos || comma == std::string::npos || comma > colon)
    argsError("RANGE", "render rotate: the range is START,END:STEPS (e.g. 15,59:60), got '" + range + "'");
  r.start = std::int32_t(parseInteger("-start", range.substr(0, comma), INT32_MIN, INT32_MAX));
  r.end = std::int32_t(parseInteger("-end", range.substr(comma + 1, colon - comma - 1), INT32_MIN, INT32_MAX));
  r.stepsPerTurn = std::uint32_t(parseInteger("-steps", range.substr(colon + 1), 0, UINT32_MAX));
  checkRotation(r);
  if (reduction) {
    if (r.start != r.end) argsError("RANGE", "render rotate -interactive: one view only, K,K:N; got '" + range + "'");
    s.render(proto::RenderInteractive{*reduction, r.axis, r.start, r.stepsPerTurn}, 2,
             "rotate " + axisText + " " + range + " -interactive");
    Tcl_SetObjResult(interp, Tcl_NewIntObj(2));
    return TCL_OK;
  }
  const std::uint32_t frames = r.frameCount();
  s.render(r, frames, "rotate " + axisText + " " + range);
  Tcl_SetObjResult(interp, Tcl_NewWideIntObj(frames));
  return TCL_OK;
}

// :s performance memory ?cluster? ?INDEX?
// :s performance comp ?cluster? ?latency? ?INDEX?
// :s performance cache ?cluster? ?INDEX?
int performanceCmd(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  // In the order of the PerformanceQuery values.
  static const char* const kQueries[] = {"memory", "comp", "cache", nullptr};
  if (objc < 3 || objc > 6) {
    Tcl_WrongNumArgs(interp, 2, objv, usageOf(objv));
    return TCL_ERROR;
  }
  int query = 0;
  if (Tcl_GetIndexFromObj(interp, objv[2], kQueries, "performance query", 0, &query) != TCL_OK)
    throw TclError({"PVR", "ARGS", "PERFORMANCE"}, Tcl_GetStringResult(interp));
  std::uint32_t cluster = proto::kAllClusters;
  for (int i = 3; i < objc; ++i) {
    const std::string w = str(objv[i]);
    if (w == "cluster" || (query == 1 && w == "latency")) continue;
    if (w == "all") continue;
    cluster = std::uint32_t(parseInteger("-cluster", w, 0, 0xFFFFFFFEL));
  }
  s.requireOpen("performance");
  const auto replies = s.query(proto::PerformanceRequest{proto::PerformanceQuery(query), cluster}, 120);
  for (const auto& m : replies)
    if (const auto* r = std::get_if<proto::PerformanceReply>(&m)) {
      if (auto deep = proto::checkJsonDepth(r->json, "performance reply"))
        throw TclError({"PVR", "PROTOCOL", "MALFORMED_PAYLOAD"}, deep->text);
      nlohmann::json doc;
      try {
        doc = nlohmann::json::parse(r->json);
      } catch (const std::exception& e) {
        throw TclError({"PVR", "PROTOCOL", "MALFORMED_PAYLOAD"}, std::string("performance reply is not JSON: ") + e.what());
      }
      Tcl_SetObjResult(interp, jsonToTcl(doc.contains("clusters") ? doc["clusters"] : doc));
      return TCL_OK;
    }
  throw TclError({"PVR", "PROTOCOL", "UNEXPECTED_MESSAGE"}, "performance: the server sent no PerformanceReply");
}

// :s camera: the camera in force (session_camera.cpp).
int cameraCmd(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  if (objc != 2) {
    Tcl_WrongNumArgs(interp, 2, objv, nullptr);
    return TCL_ERROR;
  }
  Tcl_SetObjResult(interp, s.cameraObj());
  return TCL_OK;
}

int cancelCmd(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  if (objc != 2) {
    Tcl_WrongNumArgs(interp, 2, objv, usageOf(objv));
    return TCL_ERROR;
  }
  Tcl_SetObjResult(interp, Tcl_NewIntObj(s.cancel()));
  return TCL_OK;
}

// :s wait ?-timeout S?
int waitCmd(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  if (objc != 2 && objc != 4) {
    Tcl_WrongNumArgs(interp, 2, objv, usageOf(objv));
    return TCL_ERROR;
  }
  double timeout = 1e6;
  if (objc == 4) {
    static const char* const kOptions[] = {"-timeout", nullptr};
    int index = 0;
    if (Tcl_GetIndexFromObj(interp, objv[2], kOptions, "option", 0, &index) != TCL_OK)
      throw TclError({"PVR", "ARGS", "OPTION"}, Tcl_GetStringResult(interp));
    timeout = parseNumbers("-timeout", str(objv[3]), 1)[0];
    if (!(timeout > 0)) argsError("TIMEOUT", "-timeout must be > 0 seconds");
  }
  Tcl_SetObjResult(interp, Tcl_NewWideIntObj(Tcl_WideInt(s.wait(timeout))));
  return TCL_OK;
}

int timingCmd(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  if (objc != 2) {
    Tcl_WrongNumArgs(interp, 2, objv, usageOf(objv));
    return TCL_ERROR;
  }
  Tcl_SetObjResult(interp, s.timingObj());
  return TCL_OK;
}

// :s notify ?PROC?: PROC event details... for done, cancelled and error.
int notifyCmd(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  if (objc != 2 && objc != 3) {
    Tcl_WrongNumArgs(interp, 2, objv, usageOf(objv));
    return TCL_ERROR;
  }
  if (objc == 2) {
    Tcl_SetObjResult(interp, s.notify_ ? s.notify_ : Tcl_NewObj());
    return TCL_OK;
  }
  if (s.notify_) Tcl_DecrRefCount(s.notify_);
  s.notify_ = nullptr;
  if (*Tcl_GetString(objv[2])) {
    s.notify_ = objv[2];
    Tcl_IncrRefCount(s.notify_);
  }
  return TCL_OK;
}

int helpCmd(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]);

const Subcommand kSubcommands[] = {
    {"camera", cameraCmd, "", "the camera in force (automatic or set) as a dict"},
    {"cancel", cancelCmd, "", "stop the sequence in flight; returns the frames that will still come"},
    {"close", closeCmd, "", "end the session and its MPI job"},
    {"help", helpCmd, "?subcommand?", "this help; with a subcommand, its usage (and, for set and volume, every option)"},
    {"image", imageCmd, "window|callback|file|dir ?value? | file movie.gif|movie.mp4 -fps n",
     "where frames go: a Tk photo, a callback, numbered files or a directory (no value: the current one);"
     " -fps: the animation's frames per second, 1 to 120 (default 10)"},
    {"info", infoCmd, "", "the loaded dataset: dims, spacing, origin, bounds, dtype, range and histogram"},
    {"list", listCmd, "status|datasets ?-steps|-details?", "the session's status, or the server's datasets"},
    {"notify", notifyCmd, "?command?", "call COMMAND event details... on done, cancelled and error"},
    {"open", openCmd, "host?:port? ?-ranks n? ?-account name? ?-token-file file? ?-timeout seconds?",
     "connect to pvrd (port 7350 by default) and start a job of N ranks"},
    {"performance", performanceCmd,
     "memory ?cluster? ?index? | comp ?cluster? ?latency? ?index? | cache ?cluster? ?index?",
     "memory, compositing or cache figures of the clusters"},
    {"render", renderCmd,
     "rotate axis start,end:steps ?-interactive? | time start,end?:stride? | steps n ?-every k? | frame ?-interactive?",
     "render one frame, a rotation, time steps, or a computation's next n steps (a frame every k-th and of the "
     "last); returns the number of frames"},
    {"set", setCmd, "option ?value option value ...?",
     "change settings (no argument: every option with its value and default; one: its value)"},
    {"timing", timingCmd, "", "the timings of the latest sequence, one dict per frame"},
    {"volume", volumeCmd, "add|configure|list|remove ?arg ...?",
     "the scene's volumes, each with its own data, transfer function and visibility"},
    {"wait", waitCmd, "?-timeout seconds?", "run the event loop until the sequences and settings are done"},
    {nullptr, nullptr}};

const char* usageOf(Tcl_Obj* const objv[]) {
  for (const Subcommand* c = kSubcommands; c->name; ++c)
    if (c->name == std::string_view(Tcl_GetString(objv[1]))) return c->usage && *c->usage ? c->usage : nullptr;
  return nullptr;
}

// :s help ?SUBCOMMAND?: every subcommand with its usage and summary, from
// kSubcommands; one subcommand's, and for `set` and `volume` every option too.
int helpCmd(Session& s, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  if (objc > 3) {
    Tcl_WrongNumArgs(interp, 2, objv, usageOf(objv));
    return TCL_ERROR;
  }
  const std::string text = subcommandHelp(s.name_, objc == 3 ? Tcl_GetString(objv[2]) : "");
  Tcl_SetObjResult(interp, Tcl_NewStringObj(text.c_str(), int(text.size()) - 1));  // no final newline
  return TCL_OK;
}

}  // namespace

std::string subcommandHelp(const std::string& object, const std::string& subcommand) {
  std::string text;
  for (const Subcommand* c = kSubcommands; c->name; ++c) {
    if (!subcommand.empty() && subcommand != c->name) continue;
    text += object + " " + c->name + (c->usage && *c->usage ? " " + std::string(c->usage) : "") + "\n    " +
            (c->summary ? c->summary : "?") + "\n";
  }
  if (text.empty()) {
    std::string names;
    for (const Subcommand* c = kSubcommands; c->name; ++c) names += std::string(names.empty() ? "" : ", ") + c->name;
    throw TclError({"PVR", "ARGS", "SUBCOMMAND"}, "help: no subcommand \"" + subcommand + "\"; there are " + names);
  }
  if (subcommand == "set") text += "options:\n" + optionsHelp();
  if (subcommand == "volume") text += volumeHelp(object);
  if (subcommand.empty()) text += "(" + object + " help SUBCOMMAND for one; docs/pvrsh.md and man pvrsh for more)\n";
  return text;
}

int Session::objCmd(ClientData data, Tcl_Interp* interp, int objc, Tcl_Obj* const objv[]) {
  auto* self = static_cast<Session*>(data);
  if (objc < 2) {
    Tcl_WrongNumArgs(interp, 1, objv, "subcommand ?arg ...?");
    return TCL_ERROR;
  }
  int index = 0;
  if (Tcl_GetIndexFromObjStruct(interp, objv[1], kSubcommands, sizeof(Subcommand), "subcommand", 0, &index) != TCL_OK) {
    Tcl_SetErrorCode(interp, "PVR", "ARGS", "SUBCOMMAND", nullptr);
    return TCL_ERROR;
  }
  Tcl_Preserve(self);
  int rc = TCL_ERROR;
  try {
    rc = kSubcommands[index].handler(*self, interp, objc, objv);
    if (rc == TCL_ERROR)  // only Tcl_WrongNumArgs returns without throwing
      Tcl_SetErrorCode(interp, "PVR", "ARGS", "WRONGNUM", nullptr);
  } catch (const TclError& e) {
    rc = setError(interp, e);
  } catch (const std::exception& e) {
    rc = setError(interp, {"PVR", "INTERNAL"}, std::string(kSubcommands[index].name) + ": " + e.what());
  }
  Tcl_Release(self);
  return rc;
}

}  // namespace pvr::tcl
