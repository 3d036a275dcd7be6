// Session: what comes back from the server. Each decoded message is matched
// to its request: a frame or error of a render sequence, the answer of a
// query or the failure of a SetScene, or (request id 0) news about the
// connection itself. Errors nobody waits for are reported as `wait` errors,
// `notify` events or background errors, in that order of preference.
#include "session.h"

namespace pvr::tcl {

namespace {

// Non-final replies one request may have (a SessionOpen waiting in a batch
// queue gets one per change of state; nothing else gets more than a few).
constexpr std::size_t kMaxRepliesPerRequest = 1000;

}  // namespace
namespace {

TclError remoteError(const proto::ErrorMessage& e) {
  const std::string code(proto::errorCodeName(e.code));
  return TclError({"PVR", "REMOTE", code}, "server error " + code + ": " + e.text);
}

}  // namespace

void Session::onMessage(const proto::Decoded& d) {
  const std::uint32_t id = d.info.requestId;
  Tcl_Preserve(this);
  try {
    if (id == 0) {
      // About the connection itself: an Error, or Close. An Error here
      // fails whatever waits (open's handshake); an open session reports it.
      if (const auto* e = std::get_if<proto::ErrorMessage>(&d.message)) {
        lastFailure_ = remoteError(*e);
        for (auto& [pid, p] : pending_)
          if (p.synchronous && !p.done) {
            p.error = lastFailure_;
            p.done = true;
          }
        if (state_ == State::kOpen) report(*lastFailure_);
      }
      if (const auto* c = std::get_if<proto::Close>(&d.message)) closeReason_ = c->reason;
    } else if (dropped_.count(id)) {
      if (d.info.final() || std::holds_alternative<proto::ErrorMessage>(d.message)) dropped_.erase(id);
    } else if (auto s = sequences_.find(id); s != sequences_.end()) {
      if (const auto* f = std::get_if<proto::ImageFrame>(&d.message)) {
        handleFrame(s->second, *f, d.info.final());
      } else if (const auto* e = std::get_if<proto::ErrorMessage>(&d.message)) {
        finishSequence(id);
        if (e->code != proto::ErrorCode::kCancelled) report(remoteError(*e));
      } else {
        finishSequence(id);
        report(TclError({"PVR", "PROTOCOL", "UNEXPECTED_MESSAGE"}, "a render request was answered with a message that is no image"));
      }
    } else if (auto p = pending_.find(id); p != pending_.end()) {
      Pending& pending = p->second;
      if (const auto* e = std::get_if<proto::ErrorMessage>(&d.message)) {
        pending.error = remoteError(*e);
        pending.done = true;
      } else {
        if (const auto* r = std::get_if<proto::SessionReady>(&d.message)) {
          ranks_ = r->rankCount;
          layout_ = r->clusters;
        }
        if (pending.replies.size() >= kMaxRepliesPerRequest) {
          // A server that never ends a request would grow this without
          // bound (3.1 GiB in 7 s): the session ends instead.
          onFailure(TclError({"PVR", "PROTOCOL", "LIMIT_EXCEEDED"},
                             peer_ + " sent more than " + std::to_string(kMaxRepliesPerRequest) +
                                 " replies to one request without ending it; the session is closed"));
          conn_.reset();
          return;
        }
        pending.replies.push_back(d.message);
        pending.done = d.info.final();
      }
      if (pending.done && !pending.synchronous) {
        const std::optional<TclError> error = pending.error;
        pending_.erase(p);
        if (error) report(*error);
      }
    }
  } catch (const TclError& e) {
    report(e);
  } catch (const std::exception& e) {
    report(TclError({"PVR", "INTERNAL"}, e.what()));
  }
  Tcl_Release(this);
}

void Session::onFailure(const TclError& error) {
  if (deleted_) return;
  Tcl_Preserve(this);
  // A server's Error that preceded the close says more than "connection lost".
  TclError e = lastFailure_ && lastFailure_->code().size() > 1 && lastFailure_->code()[1] == "REMOTE" ? *lastFailure_ : error;
  if (!closeReason_.empty() && e.code().size() > 2 && e.code()[2] == "LOST")
    e = TclError(e.code(), e.what() + std::string(" (") + closeReason_ + ")");
  const bool wasOpen = state_ == State::kOpen;
  state_ = State::kFailed;
  lastFailure_ = e;
  for (auto& [id, p] : pending_)
    if (!p.done) {
      p.error = e;
      p.done = true;
    }
  for (auto it = pending_.begin(); it != pending_.end();)
    it = it->second.synchronous ? std::next(it) : pending_.erase(it);
  const bool hadSequences = !sequences_.empty();
  std::vector<std::uint32_t> ids;
  for (const auto& [id, seq] : sequences_) ids.push_back(id);
  for (std::uint32_t id : ids) finishSequence(id);
  if (wasOpen || hadSequences) report(e);
  Tcl_Release(this);
}

void Session::finishSequence(std::uint32_t id) {
  const auto it = sequences_.find(id);
  if (it == sequences_.end()) return;
  Sequence seq = std::move(it->second);
  sequences_.erase(it);
  last_ = seq;
  if (progressOn(interp_) && !seq.frames.empty()) printTable(seq);
  if (!files_.empty() && !seq.cancelled) assembleAnimation(seq);
  notify(seq.cancelled ? "cancelled" : "done", {Tcl_NewWideIntObj(Tcl_WideInt(seq.frames.size()))});
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
