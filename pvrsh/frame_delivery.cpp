// Session: one arrived frame into the image sinks (`image window`, `dir`,
// `file`, `callback`), and the animated file ffmpeg assembles after a
// sequence written with `image file out.gif|.mp4`.
#include <cstdio>

#include "session.h"

namespace pvr::tcl {

void Session::handleFrame(std::uint32_t id, const proto::ImageFrame& f, bool complete) {
  // The frame is recorded (ReplyBook::route); a sink that fails ends the
  // sequence with its error rather than leave it in flight for ever
  // (issue 15, finding 14: a failure on the last frame kept every later
  // `wait` busy).
  const std::size_t count = book_.sequences.at(id).frames.size();
  try {
    const std::uint64_t number = framesReceived_++;
    const Pixels pixels = decodePixels(f);
    // An interactive render's coarse frame comes at 1/r of the image size
    // per axis; the window and files show it zoomed to the image size,
    // which the session set (docs/pvrsh.md).
    const int zoom = book_.sequences.at(id).frames.back().reduction;
    const auto [width, height] = zoom > 1 ? imageSize(accepted_) : std::pair{pixels.width, pixels.height};
    // Sinks: the photo, then files, then the callback (which may look at both).
    if (!photo_.empty()) putPhoto(interp_, photo_, pixels, zoom, width, height);
    if (!dir_.empty() || !files_.empty()) {
      const Pixels shown = zoom > 1 ? zoomPixels(pixels, zoom, width, height) : Pixels{};
      const Pixels& written = zoom > 1 ? shown : pixels;
      if (!dir_.empty()) writePng(written, numberedInDirectory(dir_, name_).name(number));
      if (!files_.empty()) {
        writePng(written, files_.name(number));
        if (count == 1) firstFileNumber_ = number;
      }
    }
  } catch (const TclError& e) {
    abandonSequence(id, complete, e);
    return;
  }
  if (progressOn(interp_)) printProgress(book_.sequences.at(id));
  if (callback_) {
    const FrameRecord record = book_.sequences.at(id).frames.back();  // the callback may add frames
    runImageCallback(record);
    if (deleted_) return;  // the callback deleted this session
  }
  // The callback may have cancelled or closed: finishing is then done.
  if (complete) finishSequence(id);
}

void Session::abandonSequence(std::uint32_t id, bool complete, const TclError& error) {
  if (book_.sequences.count(id) == 0) return;
  stopSequence(id, complete);
  report(error);
}

void Session::stopSequence(std::uint32_t id, bool complete) {
  const auto it = book_.sequences.find(id);
  if (it == book_.sequences.end()) return;
  // The sequence ends first, whatever sending the Cancel then meets; the
  // frames still to come are dropped.
  it->second.cancelled = true;
  if (!complete) book_.drop(id);
  finishSequence(id);
  // The server stops making them (the `done` notification may have closed
  // or deleted the session: then there is no one to tell).
  if (!complete && conn_ && conn_->connected()) {
    try {
      send(proto::Cancel{id}, false);
    } catch (const TclError&) {
      // The connection is going: its own failure is reported.
    }
  }
}

void Session::runImageCallback(const FrameRecord& r) {
  Tcl_Obj* cmd = Tcl_DuplicateObj(callback_);
  Tcl_IncrRefCount(cmd);
  Tcl_ListObjAppendElement(nullptr, cmd, Tcl_NewWideIntObj(r.frame));
  Tcl_ListObjAppendElement(nullptr, cmd, timingDict(r));
  Tcl_InterpState saved = Tcl_SaveInterpState(interp_, TCL_OK);
  const int rc = Tcl_EvalObjEx(interp_, cmd, TCL_EVAL_GLOBAL);
  Tcl_DecrRefCount(cmd);
  if (rc != TCL_OK) {
    Tcl_AddErrorInfo(interp_, "\n    (image callback of session ");
    Tcl_AddErrorInfo(interp_, name_.c_str());
    Tcl_AddErrorInfo(interp_, ")");
    // A running `wait` raises the error; otherwise it is a background error.
    if (waiters_ > 0 && !waitError_) {
      Tcl_Obj* code = Tcl_GetVar2Ex(interp_, "errorCode", nullptr, TCL_GLOBAL_ONLY);
      std::vector<std::string> codeList{"PVR", "CALLBACK"};
      if (code) codeList.push_back(Tcl_GetString(code));
      waitError_ = TclError(codeList, std::string("image callback failed: ") + Tcl_GetStringResult(interp_));
    } else {
      Tcl_BackgroundException(interp_, rc);
    }
  }
  Tcl_RestoreInterpState(interp_, saved);
}

void Session::assembleAnimation(const Sequence& seq) {
  // The frames were written as numbered PNGs beside the target; ffmpeg,
  // where installed, turns this sequence's into the file.
  if (animatedTarget_.empty() || seq.frames.empty()) return;
  const std::string input = files_.pattern();
  Tcl_InterpState saved = Tcl_SaveInterpState(interp_, TCL_OK);
  const bool found = Tcl_Eval(interp_, "auto_execok ffmpeg") == TCL_OK && *Tcl_GetStringResult(interp_) != '\0';
  if (!found) {
    std::fprintf(stderr, "%s: ffmpeg is not installed; %s not written (the frames are %s)\n", name_.c_str(),
                 animatedTarget_.c_str(), input.c_str());
  } else {
    Tcl_Obj* cmd = Tcl_NewListObj(0, nullptr);
    Tcl_IncrRefCount(cmd);
    Tcl_ListObjAppendElement(nullptr, cmd, Tcl_NewStringObj("exec", -1));
    for (const std::string& a : ffmpegArguments(animatedTarget_, input, firstFileNumber_, animationFps_))
      Tcl_ListObjAppendElement(nullptr, cmd, Tcl_NewStringObj(a.c_str(), -1));
    Tcl_ListObjAppendElement(nullptr, cmd, Tcl_NewStringObj("2>@1", -1));
    if (Tcl_EvalObjEx(interp_, cmd, TCL_EVAL_GLOBAL) != TCL_OK)
      std::fprintf(stderr, "%s: ffmpeg could not write %s: %s\n", name_.c_str(), animatedTarget_.c_str(),
                   Tcl_GetStringResult(interp_));
    Tcl_DecrRefCount(cmd);
  }
  Tcl_RestoreInterpState(interp_, saved);
}

}  // namespace pvr::tcl
