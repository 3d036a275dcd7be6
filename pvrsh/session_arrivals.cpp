// Session: what comes back from the server. Each decoded message is matched
// to its request: a frame or error of a render sequence, the answer of a
// query or the failure of a SetScene, or (request id 0) news about the
// connection itself. Errors nobody waits for are reported as `wait` errors,
// `notify` events or background errors, in that order of preference.
#include "session.h"

namespace pvr::tcl {

void Session::onMessage(const proto::Decoded& d) {
  Tcl_Preserve(this);
  try {
    Arrival arrival = book_.route(d, Clock::now());
    if (const auto* r = std::get_if<proto::SessionReady>(&d.message); r && arrival.kind == Arrival::Kind::kAnswered) {
      ranks_ = r->rankCount;
      layout_ = r->clusters;
    }
    act(arrival);
  } catch (const TclError& e) {
    report(e);
  } catch (const std::exception& e) {
    report(TclError({"PVR", "INTERNAL"}, e.what()));
  }
  Tcl_Release(this);
}

void Session::onRefused(const FrameIntake::Refused& frame) {
  // A reply over pvrsh's limit (a catalog over 4 MiB): the connection
  // skipped it, so only the request it answered fails.
  Tcl_Preserve(this);
  const std::string code(proto::errorCodeName(frame.error.code));
  const std::string what = peer_ + " sent a " + std::string(frame.type) + " pvrsh refuses (" + frame.error.text + ")";
  Arrival arrival = book_.refuse(frame.header.requestId, (frame.header.flags & proto::kFlagFinal) != 0,
                                 TclError({"PVR", "PROTOCOL", code}, what + "; it was skipped and the session serves on"));
  // Not the answer of a request pvrsh knows: what it missed cannot be told.
  if (arrival.kind == Arrival::Kind::kConnectionError)
    endSession(TclError({"PVR", "PROTOCOL", code}, what + "; the session is closed"));
  else
    act(arrival);
  Tcl_Release(this);
}

void Session::act(Arrival& a) {
  switch (a.kind) {
    case Arrival::Kind::kIgnored:
    case Arrival::Kind::kAnswered:
      return;
    case Arrival::Kind::kConnectionError:
      // open's handshake fails with it; an open session reports it.
      lastFailure_ = a.error;
      if (state_ == State::kOpen) report(*a.error);
      return;
    case Arrival::Kind::kClosed: {
      // The server ends the session, whether or not it closes the socket
      // too: nothing more will be served. An Error it sent just before
      // says why better than the Close does.
      closeReason_ = a.reason;
      TclError e({"PVR", "CONNECT", "CLOSED"}, "session " + name_ + ": " + peer_ + " closed the session: " +
                                                   (a.reason.empty() ? std::string("no reason given") : a.reason));
      if (lastFailure_ && lastFailure_->code().size() > 1 && lastFailure_->code()[1] == "REMOTE") e = *lastFailure_;
      // The session ends first, then pvrsh answers with its own Close
      // (docs/protocol.md) and closes the socket.
      onFailure(e);
      if (conn_ && conn_->connected()) conn_->send(proto::Close{"pvrsh: the server closed the session"}, 0);
      conn_.reset();
      return;
    }
    case Arrival::Kind::kFrame:
      handleFrame(a.id, *a.frame, a.complete);
      return;
    case Arrival::Kind::kSequenceEnded:
      // A frame of it refused for its size ends it as a sink error does:
      // the server is asked to stop. An Error or odd answer ended it already.
      if (a.error && a.error->code().size() > 1 && a.error->code()[1] == "PROTOCOL" &&
          a.error->code().back() == "FRAME_TOO_LARGE") {
        abandonSequence(a.id, a.complete, *a.error);
      } else {
        finishSequence(a.id);
        if (a.error) report(*a.error);
      }
      return;
    case Arrival::Kind::kRequestDone:
      if (const auto error = settled(a.id, a.error)) report(*error);
      return;
    case Arrival::Kind::kTooManyReplies:
      endSession(*a.error);
      return;
  }
}

void Session::endSession(const TclError& error) {
  onFailure(error);
  conn_.reset();
}

void Session::onFailure(const TclError& error) {
  // Once: a session that ended (a Close, a flood) and then fails to send
  // its goodbye has nothing more to report.
  if (deleted_ || state_ == State::kFailed) return;
  Tcl_Preserve(this);
  // A server's Error that preceded the close says more than "connection lost".
  TclError e = lastFailure_ && lastFailure_->code().size() > 1 && lastFailure_->code()[1] == "REMOTE" ? *lastFailure_ : error;
  if (!closeReason_.empty() && e.code().size() > 2 && e.code()[2] == "LOST")
    e = TclError(e.code(), e.what() + std::string(" (") + closeReason_ + ")");
  const bool wasOpen = state_ == State::kOpen;
  state_ = State::kFailed;
  lastFailure_ = e;
  book_.failPending(e);
  forgetSent();
  const bool hadSequences = !book_.sequences.empty();
  std::vector<std::uint32_t> ids;
  for (const auto& [id, seq] : book_.sequences) ids.push_back(id);
  for (std::uint32_t id : ids) finishSequence(id);
  if (wasOpen || hadSequences) report(e);
  Tcl_Release(this);
}

void Session::finishSequence(std::uint32_t id) {
  std::optional<Sequence> seq = book_.finish(id);
  if (!seq) return;
  const std::size_t frames = seq->frames.size();
  const bool cancelled = seq->cancelled;
  if (progressOn(interp_) && frames > 0) printTable(*seq);
  if (!files_.empty() && !cancelled) assembleAnimation(*seq);
  book_.remember(std::move(*seq));
  notify(cancelled ? "cancelled" : "done", {Tcl_NewWideIntObj(Tcl_WideInt(frames))});
}

void Session::report(const TclError& error) {
  if (waiters_ > 0) {
    if (!waitError_) waitError_ = error;
    return;
  }
  if (notify_) {
    notify("error", {Tcl_NewStringObj(error.what(), -1), listOf(error.code())});
    return;
  }
  Tcl_InterpState saved = Tcl_SaveInterpState(interp_, TCL_OK);
  setError(interp_, error);
  Tcl_AddErrorInfo(interp_, ("\n    (session " + name_ + ")").c_str());
  Tcl_BackgroundException(interp_, TCL_ERROR);
  Tcl_RestoreInterpState(interp_, saved);
}

void Session::notify(const char* event, std::vector<Tcl_Obj*> details) {
  if (!notify_) {
    for (Tcl_Obj* o : details) {  // frees the unused objects
      Tcl_IncrRefCount(o);
      Tcl_DecrRefCount(o);
    }
    return;
  }
  Tcl_Obj* cmd = Tcl_DuplicateObj(notify_);
  Tcl_IncrRefCount(cmd);
  Tcl_ListObjAppendElement(nullptr, cmd, Tcl_NewStringObj(event, -1));
  for (Tcl_Obj* o : details) Tcl_ListObjAppendElement(nullptr, cmd, o);
  Tcl_InterpState saved = Tcl_SaveInterpState(interp_, TCL_OK);
  if (Tcl_EvalObjEx(interp_, cmd, TCL_EVAL_GLOBAL) != TCL_OK) Tcl_BackgroundException(interp_, TCL_ERROR);
  Tcl_RestoreInterpState(interp_, saved);
  Tcl_DecrRefCount(cmd);
}

}  // namespace pvr::tcl
