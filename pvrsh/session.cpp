// Session: its lifetime, the requests it sends, and waiting for their
// answers on the event loop.
#include "session.h"

#include <algorithm>

namespace pvr::tcl {

Session::Session(Tcl_Interp* interp, std::string name) : interp_(interp), name_(std::move(name)) {}

Session::~Session() {
  conn_.reset();
  if (callback_) Tcl_DecrRefCount(callback_);
  if (notify_) Tcl_DecrRefCount(notify_);
}

void Session::deleteCmd(ClientData data) {
  auto* self = static_cast<Session*>(data);
  self->deleted_ = true;
  self->token_ = nullptr;
  self->conn_.reset();  // closing the socket ends the server's job
  self->state_ = State::kClosed;
  Tcl_EventuallyFree(self, freeProc);
}

void Session::freeProc(char* data) { delete reinterpret_cast<Session*>(data); }

bool Session::runEventsUntil(const std::function<bool()>& done, double timeoutSeconds) {
  bool timedOut = false;
  const Tcl_TimerToken timer = Tcl_CreateTimerHandler(
      int(std::min(timeoutSeconds, 1e6) * 1000), [](ClientData flag) { *static_cast<bool*>(flag) = true; }, &timedOut);
  while (!done() && !timedOut && !deleted_) Tcl_DoOneEvent(TCL_ALL_EVENTS);
  Tcl_DeleteTimerHandler(timer);
  if (deleted_) throw TclError({"PVR", "STATE", "DELETED"}, "session " + name_ + " was deleted while waiting");
  return !timedOut || done();
}

void Session::requireOpen(const char* what) const {
  if (state_ != State::kOpen)
    throw TclError({"PVR", "STATE", "NOTOPEN"},
                   std::string(what) + ": session " + name_ + " is not open (use: " + name_ + " open HOST:PORT)");
}

std::uint32_t Session::send(const proto::Message& message, bool synchronous) {
  const std::uint32_t id = nextId_++;
  if (!proto::isRenderRequest(message)) book_.expect(id, synchronous);
  if (!conn_ || !conn_->send(message, id)) {
    book_.pending.erase(id);
    throw TclError({"PVR", "CONNECT", "LOST"}, "session " + name_ + ": the connection is gone");
  }
  return id;
}

std::vector<proto::Message> Session::query(const proto::Message& request, double timeoutSeconds,
                                           const std::function<void(const proto::Message&)>& onProgress) {
  const std::uint32_t id = send(request, true);
  std::size_t seen = 0;  // answers handed to onProgress
  bool answered = false;
  for (;;) {
    // Until the FINAL answer, or (with onProgress) until one more answer.
    answered = runEventsUntil(
        [&] {
          const auto it = book_.pending.find(id);
          return it == book_.pending.end() || it->second.done || (onProgress && it->second.replies.size() > seen);
        },
        timeoutSeconds);
    const auto it = book_.pending.find(id);
    if (it == book_.pending.end()) break;
    // Progress: every answer but a FINAL one (an Error is kept apart), also
    // those that arrived together with it.
    const Pending& p = it->second;
    const std::size_t progress = p.replies.size() - (p.done && !p.error && !p.replies.empty() ? 1 : 0);
    while (onProgress && seen < progress) onProgress(p.replies[seen++]);
    if (!answered || p.done) break;
  }
  const auto it = book_.pending.find(id);
  if (it == book_.pending.end()) throw TclError({"PVR", "CONNECT", "LOST"}, "session " + name_ + ": the connection is gone");
  Pending p = std::move(it->second);
  book_.pending.erase(it);
  if (!answered) throw TclError({"PVR", "TIMEOUT"}, "session " + name_ + ": no answer from " + peer_ + " in time");
  if (p.error) throw *p.error;
  return p.replies;
}

void Session::close(const std::string& reason) {
  if (conn_ && conn_->connected()) conn_->send(proto::Close{reason}, 0);
  conn_.reset();
  book_.clear();
  forgetSent();
  state_ = State::kClosed;
}

void Session::applySettings(const SettingsChange& change) {
  if (state_ != State::kOpen) return;  // sent by open
  if (change.dataset || !change.patch.empty()) sendScene(change);
  settings_.cameraMoves = nlohmann::json::array();  // sent: moves apply once
  // Figure 5 sets render and compositing clusters in two commands; the
  // layout goes out whole with the next render, so no half layout is sent.
  if (change.layout) layoutPending_ = true;
}

std::uint32_t Session::render(const proto::Message& request, std::uint32_t total, const std::string& label) {
  requireOpen("render");
  // The rule of docs/pvrsh.md, "Refused settings": no frame of settings
  // the user did not ask for.
  if (refusal_)
    throw TclError(refusal_->code(), "render: session " + name_ + ": " + refusal_->what() +
                                         "; set a value the server accepts (or set the option again) first");
  if (layoutPending_) {
    layoutsSent_[send(proto::SetLayout{settings_.clusters}, false)] = settings_.clusters;
    layoutPending_ = false;
  }
  const std::uint32_t id = send(request, false);
  const auto* interactive = std::get_if<proto::RenderInteractive>(&request);
  book_.start(id, label, total, Clock::now()).reduction = interactive ? int(interactive->reduction) : 0;
  return id;
}

int Session::cancel() {
  int n = 0;
  std::vector<std::uint32_t> ids;
  for (auto& [id, seq] : book_.sequences) ids.push_back(id);
  for (std::uint32_t id : ids) {
    if (conn_ && conn_->connected()) send(proto::Cancel{id}, false);
    book_.drop(id);
    book_.sequences[id].cancelled = true;
    finishSequence(id);
    ++n;
  }
  return n;
}

std::size_t Session::wait(double timeoutSeconds) {
  Tcl_Preserve(this);
  ++waiters_;
  std::size_t frames = 0;
  // The sequence this wait reports: the oldest in flight, else one that
  // finished before the wait began (the event loop may have run it to the
  // end while another session was waited for) and no wait has reported.
  const std::uint32_t firstId = !book_.sequences.empty()   ? book_.sequences.begin()->first
                                : book_.latest().id > waitedId_ ? book_.latest().id
                                                                : nextId_;
  const auto busy = [&] { return !waitError_ && book_.busy(); };
  bool inTime = true;
  try {
    inTime = runEventsUntil([&] { return !busy(); }, timeoutSeconds);
  } catch (...) {
    --waiters_;
    Tcl_Release(this);
    throw;
  }
  --waiters_;
  std::optional<TclError> error;
  if (waiters_ == 0) std::swap(error, waitError_);
  if (const Sequence& latest = book_.latest(); latest.id >= firstId) {
    frames = latest.frames.size();
    waitedId_ = latest.id;
  }
  Tcl_Release(this);
  if (error) throw *error;
  if (!inTime) throw TclError({"PVR", "TIMEOUT"}, "wait: session " + name_ + " still busy after " +
                                                      std::to_string(timeoutSeconds) + " s");
  return frames;
}

}  // namespace pvr::tcl
