#include "session.h"

#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace pvr::tcl {
namespace {

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

std::string remoteName(proto::ErrorCode code) { return std::string(proto::errorCodeName(code)); }

TclError remoteError(const proto::ErrorMessage& e) {
  return TclError({"PVR", "REMOTE", remoteName(e.code)}, "server error " + remoteName(e.code) + ": " + e.text);
}

// The shared token of a token file (trailing whitespace dropped).
std::string readToken(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw TclError({"PVR", "CONNECT", "TOKEN"}, "cannot read token file " + path);
  std::ostringstream s;
  s << in.rdbuf();
  std::string token = s.str();
  while (!token.empty() && std::isspace(static_cast<unsigned char>(token.back()))) token.pop_back();
  if (token.empty()) throw TclError({"PVR", "CONNECT", "TOKEN"}, "token file " + path + " is empty");
  return token;
}

bool progressOn(Tcl_Interp* interp) {
  const char* v = Tcl_GetVar2(interp, "::pvr::progress", nullptr, TCL_GLOBAL_ONLY);
  int on = 0;
  return v && Tcl_GetBoolean(nullptr, v, &on) == TCL_OK && on;
}

Tcl_Obj* timingDict(const FrameRecord& r) {
  Tcl_Obj* d = Tcl_NewDictObj();
  const auto put = [&](const char* k, double v) { Tcl_DictObjPut(nullptr, d, Tcl_NewStringObj(k, -1), Tcl_NewDoubleObj(v)); };
  put("dist", r.timing.distribute);
  put("rend", r.timing.render);
  put("comp", r.timing.composite);
  put("comm", r.timing.communicate);
  put("send", r.timing.send);
  put("arrival", r.arrival);
  Tcl_DictObjPut(nullptr, d, Tcl_NewStringObj("width", -1), Tcl_NewIntObj(r.width));
  Tcl_DictObjPut(nullptr, d, Tcl_NewStringObj("height", -1), Tcl_NewIntObj(r.height));
  return d;
}

}  // namespace

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

template <class Done>
bool Session::runEventsUntil(Done done, double timeoutSeconds) {
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
  if (!std::holds_alternative<proto::RenderFrame>(message) && !std::holds_alternative<proto::RenderRotation>(message))
    pending_[id].synchronous = synchronous;
  if (!conn_ || !conn_->send(message, id)) {
    pending_.erase(id);
    throw TclError({"PVR", "CONNECT", "LOST"}, "session " + name_ + ": the connection is gone");
  }
  return id;
}

std::vector<proto::Message> Session::query(const proto::Message& request, double timeoutSeconds) {
  const std::uint32_t id = send(request, true);
  const bool answered = runEventsUntil(
      [&] {
        const auto it = pending_.find(id);
        return it == pending_.end() || it->second.done;
      },
      timeoutSeconds);
  const auto it = pending_.find(id);
  if (it == pending_.end()) throw TclError({"PVR", "CONNECT", "LOST"}, "session " + name_ + ": the connection is gone");
  Pending p = std::move(it->second);
  pending_.erase(it);
  if (!answered) throw TclError({"PVR", "TIMEOUT"}, "session " + name_ + ": no answer from " + peer_ + " in time");
  if (p.error) throw *p.error;
  return p.replies;
}

void Session::open(const std::string& host, int port, std::uint32_t ranks, const std::string& tokenFile, double timeout) {
  if (state_ == State::kOpen || state_ == State::kConnecting)
    throw TclError({"PVR", "STATE", "OPEN"}, "session " + name_ + " is already open to " + peer_ + " (close it first)");
  const std::string token = tokenFile.empty() ? std::string() : readToken(tokenFile);
  Tcl_Preserve(this);
  try {
    // Step 1: TCP connect on the event loop.
    conn_.reset();
    pending_.clear();
    sequences_.clear();
    closeReason_.clear();
    lastFailure_.reset();
    state_ = State::kConnecting;
    peer_ = host + ":" + std::to_string(port);
    conn_ = std::make_unique<Connection>(*this, host, port, std::min(timeout, 30.0));
    runEventsUntil([&] { return !conn_ || conn_->connected() || conn_->failed(); }, timeout);
    if (!conn_ || !conn_->connected()) {
      if (conn_ && !conn_->failed())
        throw TclError({"PVR", "CONNECT", "TIMEOUT"}, "cannot connect to " + peer_ + ": timed out");
      if (lastFailure_) throw *lastFailure_;
      throw TclError({"PVR", "CONNECT", "FAILED"}, "cannot connect to " + peer_);
    }
    // Step 2: Hello, Welcome, and the token challenge when the server asks.
    const auto hello = query(proto::Hello{"pvrsh " PVR_PACKAGE_VERSION}, timeout);
    const auto* welcome = std::get_if<proto::Welcome>(&hello.front());
    if (!welcome) throw TclError({"PVR", "PROTOCOL", "UNEXPECTED_MESSAGE"}, peer_ + " did not answer Hello with Welcome");
    serverSoftware_ = welcome->software;
    maxRanks_ = welcome->maxRanks;
    if (welcome->authRequired) {
      const auto* challenge = hello.size() > 1 ? std::get_if<proto::AuthChallenge>(&hello[1]) : nullptr;
      if (!challenge) throw TclError({"PVR", "PROTOCOL", "UNEXPECTED_MESSAGE"}, peer_ + " asked for a token but sent no challenge");
      if (token.empty())
        throw TclError({"PVR", "CONNECT", "TOKEN"}, peer_ + " requires a token: open with -token-file FILE");
      proto::AuthResponse response;
      unsigned int len = 0;
      HMAC(EVP_sha256(), token.data(), int(token.size()), challenge->nonce.data(), challenge->nonce.size(),
           response.mac.data(), &len);
      query(response, timeout);
    }
    // Step 3: start the MPI job with the layout set so far.
    if (ranks > 0 && maxRanks_ > 0 && ranks > maxRanks_)
      throw TclError({"PVR", "ARGS", "RANKS"}, "-ranks " + std::to_string(ranks) + " is more than " + peer_ +
                                                   " allows (" + std::to_string(maxRanks_) + ")");
    const auto ready = query(proto::SessionOpen{ranks, settings_.clusters}, std::max(timeout, 120.0));
    const auto* r = std::get_if<proto::SessionReady>(&ready.front());
    if (!r) throw TclError({"PVR", "PROTOCOL", "UNEXPECTED_MESSAGE"}, peer_ + " did not answer SessionOpen with SessionReady");
    ranks_ = r->rankCount;
    layout_ = r->clusters;
    state_ = State::kOpen;
    layoutPending_ = false;
    // Step 4: what was set before the session opened.
    if (!settings_.dataset.empty() || !settings_.scene.empty())
      send(proto::SetScene{settings_.dataset, settings_.scene.empty() ? std::string() : settings_.scene.dump()}, false);
  } catch (...) {
    if (!deleted_) {
      conn_.reset();
      pending_.clear();
      state_ = State::kFailed;
    }
    Tcl_Release(this);
    throw;
  }
  Tcl_Release(this);
}

void Session::close(const std::string& reason) {
  if (conn_ && conn_->connected()) conn_->send(proto::Close{reason}, 0);
  conn_.reset();
  pending_.clear();
  for (auto& [id, seq] : sequences_) last_ = seq;
  sequences_.clear();
  state_ = State::kClosed;
}

void Session::applySettings(const SettingsChange& change) {
  if (state_ != State::kOpen) return;  // sent by open
  if (change.dataset || !change.patch.empty())
    send(proto::SetScene{change.dataset ? settings_.dataset : std::string(),
                         change.patch.empty() ? std::string() : change.patch.dump()},
         false);
  // Figure 5 sets render and compositing clusters in two commands; the
  // layout goes out whole with the next render, so no half layout is sent.
  if (change.layout) layoutPending_ = true;
}

std::uint32_t Session::render(const proto::Message& request, std::uint32_t total, const std::string& label) {
  requireOpen("render");
  if (layoutPending_) {
    send(proto::SetLayout{settings_.clusters}, false);
    layoutPending_ = false;
  }
  const std::uint32_t id = send(request, false);
  Sequence& seq = sequences_[id];
  seq.id = id;
  seq.label = label;
  seq.total = total;
  seq.sent = Clock::now();
  last_ = seq;
  return id;
}

int Session::cancel() {
  int n = 0;
  std::vector<std::uint32_t> ids;
  for (auto& [id, seq] : sequences_) ids.push_back(id);
  for (std::uint32_t id : ids) {
    if (conn_ && conn_->connected()) send(proto::Cancel{id}, false);
    dropped_[id] = true;
    sequences_[id].cancelled = true;
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
  const std::uint32_t firstId = !sequences_.empty() ? sequences_.begin()->first
                                : last_.id > waitedId_ ? last_.id
                                                       : nextId_;
  const auto busy = [&] {
    if (waitError_) return false;
    if (!sequences_.empty()) return true;
    for (const auto& [id, p] : pending_)
      if (!p.synchronous && !p.done) return true;
    return false;
  };
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
  if (last_.id >= firstId) {
    frames = last_.frames.size();
    waitedId_ = last_.id;
  }
  Tcl_Release(this);
  if (error) throw *error;
  if (!inTime) throw TclError({"PVR", "TIMEOUT"}, "wait: session " + name_ + " still busy after " +
                                                      std::to_string(timeoutSeconds) + " s");
  return frames;
}

// ---- Arrivals ----

void Session::onMessage(const proto::Decoded& d) {
  const std::uint32_t id = d.info.requestId;
  Tcl_Preserve(this);
  try {
    if (id == 0) {
      // About the connection itself: an Error, or Close.
      // An Error here fails whatever waits (open's handshake); an open
      // session reports it.
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

void Session::handleFrame(Sequence& seq, const proto::ImageFrame& f, bool final) {
  const std::uint32_t id = seq.id;
  FrameRecord r;
  r.frame = f.frameNumber;
  r.timing = f.timing;
  r.arrival = seconds(Clock::now() - seq.sent);
  r.width = int(f.width);
  r.height = int(f.height);
  seq.frames.push_back(r);
  last_ = seq;
  const std::uint64_t number = framesReceived_++;
  const Pixels pixels = decodePixels(f);

  // Sinks: the photo, then files, then the callback (which may look at both).
  if (!photo_.empty()) putPhoto(interp_, photo_, pixels);
  const auto numbered = [&](const std::string& pattern) {
    char buf[4096];
    std::snprintf(buf, sizeof buf, pattern.c_str(), static_cast<unsigned long long>(number));
    return std::string(buf);
  };
  if (!dir_.empty()) {
    std::string base = name_;
    if (!base.empty() && base[0] == ':') base.erase(0, 1);
    writePng(pixels, numbered(dir_ + "/" + base + "_%05llu.png"));
  }
  if (!filePattern_.empty()) {
    const std::string path = numbered(filePattern_);
    writePng(pixels, path);
    if (seq.frames.size() == 1) firstFileNumber_ = number;
  }
  if (progressOn(interp_)) printProgress(seq);
  if (callback_) {
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
    if (deleted_) return;
  }
  if (final || (sequences_.count(id) && sequences_[id].frames.size() >= sequences_[id].total)) finishSequence(id);
}

void Session::finishSequence(std::uint32_t id) {
  const auto it = sequences_.find(id);
  if (it == sequences_.end()) return;
  Sequence seq = std::move(it->second);
  sequences_.erase(it);
  last_ = seq;
  if (progressOn(interp_) && !seq.frames.empty()) printTable(seq);
  if (!filePattern_.empty() && !seq.cancelled) assembleAnimation(seq);
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
    for (Tcl_Obj* o : details) Tcl_DecrRefCount(Tcl_NewListObj(1, &o));  // frees the unused objects
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

void Session::printProgress(const Sequence& seq) const {
  const double elapsed = seconds(Clock::now() - seq.sent);
  const std::size_t done = seq.frames.size();
  const double fps = elapsed > 0 ? double(done) / elapsed : 0;
  const double left = fps > 0 ? double(seq.total - std::min<std::size_t>(done, seq.total)) / fps : 0;
  const bool tty = ::isatty(2);
  std::fprintf(stderr, "%s%s %s: %zu/%u frames, %.2f fps, %.1f s left%s", tty ? "\r" : "", name_.c_str(),
               seq.label.c_str(), done, seq.total, fps, left, tty && done < seq.total ? "" : "\n");
  std::fflush(stderr);
}

void Session::printTable(const Sequence& seq) const {
  const double total = seq.frames.back().arrival;
  std::fprintf(stderr, "%s %s: %zu frames in %.3f s (%.2f fps)%s\n", name_.c_str(), seq.label.c_str(),
               seq.frames.size(), total, total > 0 ? double(seq.frames.size()) / total : 0.0,
               seq.cancelled ? ", cancelled" : "");
  std::fprintf(stderr, "%6s %9s %9s %9s %9s %9s %9s\n", "frame", "dist", "rend", "comp", "comm", "send", "arrival");
  proto::FrameTiming sum;
  for (const auto& r : seq.frames) {
    std::fprintf(stderr, "%6u %9.4f %9.4f %9.4f %9.4f %9.4f %9.4f\n", r.frame, r.timing.distribute, r.timing.render,
                 r.timing.composite, r.timing.communicate, r.timing.send, r.arrival);
    sum.distribute += r.timing.distribute;
    sum.render += r.timing.render;
    sum.composite += r.timing.composite;
    sum.communicate += r.timing.communicate;
    sum.send += r.timing.send;
  }
  const double all = sum.distribute + sum.render + sum.composite + sum.communicate + sum.send;
  const auto share = [&](double v) { return all > 0 ? 100.0 * v / all : 0.0; };
  std::fprintf(stderr, "breakdown (s, share): dist %.3f (%.0f%%)  rend %.3f (%.0f%%)  comp %.3f (%.0f%%)  "
                       "comm %.3f (%.0f%%)  send %.3f (%.0f%%)\n",
               sum.distribute, share(sum.distribute), sum.render, share(sum.render), sum.composite,
               share(sum.composite), sum.communicate, share(sum.communicate), sum.send, share(sum.send));
}

void Session::assembleAnimation(const Sequence& seq) {
  // `image file out.gif` (or .mp4): the frames were written as numbered PNGs
  // beside it; ffmpeg, where installed, turns this sequence's into the file.
  if (animatedTarget_.empty() || seq.frames.empty()) return;
  std::string input = filePattern_;
  const auto at = input.find("%05llu");
  if (at != std::string::npos) input.replace(at, 6, "%05d");
  Tcl_InterpState saved = Tcl_SaveInterpState(interp_, TCL_OK);
  const bool found = Tcl_Eval(interp_, "auto_execok ffmpeg") == TCL_OK && *Tcl_GetStringResult(interp_) != '\0';
  if (!found) {
    std::fprintf(stderr, "%s: ffmpeg is not installed; %s not written (the frames are %s)\n", name_.c_str(),
                 animatedTarget_.c_str(), input.c_str());
  } else {
    Tcl_Obj* cmd = Tcl_NewListObj(0, nullptr);
    Tcl_IncrRefCount(cmd);
    for (const std::string& a : {std::string("exec"), std::string("ffmpeg"), std::string("-y"), std::string("-loglevel"),
                                 std::string("error"), std::string("-framerate"), std::string("10"),
                                 std::string("-start_number"), std::to_string(firstFileNumber_), std::string("-i"), input,
                                 animatedTarget_, std::string("2>@1")})
      Tcl_ListObjAppendElement(nullptr, cmd, Tcl_NewStringObj(a.c_str(), -1));
    if (Tcl_EvalObjEx(interp_, cmd, TCL_EVAL_GLOBAL) != TCL_OK)
      std::fprintf(stderr, "%s: ffmpeg could not write %s: %s\n", name_.c_str(), animatedTarget_.c_str(),
                   Tcl_GetStringResult(interp_));
    Tcl_DecrRefCount(cmd);
  }
  Tcl_RestoreInterpState(interp_, saved);
}

Tcl_Obj* Session::timingObj() const {
  Tcl_Obj* list = Tcl_NewListObj(0, nullptr);
  for (const auto& r : last_.frames) {
    Tcl_Obj* d = timingDict(r);
    Tcl_DictObjPut(nullptr, d, Tcl_NewStringObj("frame", -1), Tcl_NewWideIntObj(r.frame));
    Tcl_ListObjAppendElement(nullptr, list, d);
  }
  return list;
}

Tcl_Obj* Session::statusObj() {
  static const char* const kStates[] = {"closed", "connecting", "open", "failed"};
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
  put("file", str(filePattern_));
  put("dir", str(dir_));
  put("frames_received", Tcl_NewWideIntObj(Tcl_WideInt(framesReceived_)));
  put("busy", Tcl_NewBooleanObj(!sequences_.empty()));
  Tcl_Obj* seq = Tcl_NewDictObj();
  Tcl_DictObjPut(nullptr, seq, Tcl_NewStringObj("request", -1), str(last_.label));
  Tcl_DictObjPut(nullptr, seq, Tcl_NewStringObj("done", -1), Tcl_NewWideIntObj(Tcl_WideInt(last_.frames.size())));
  Tcl_DictObjPut(nullptr, seq, Tcl_NewStringObj("total", -1), Tcl_NewWideIntObj(last_.total));
  put("sequence", seq);
  // The server's own variables, when it can answer at once (a render in
  // flight would hold the answer until it ends).
  Tcl_Obj* remote = Tcl_NewDictObj();
  if (state_ == State::kOpen && sequences_.empty()) {
    for (const auto& m : query(proto::StatusRequest{}, 30))
      if (const auto* r = std::get_if<proto::StatusReply>(&m))
        for (const auto& kv : r->entries) Tcl_DictObjPut(nullptr, remote, str(kv.key), str(kv.value));
  }
  put("remote", remote);
  return d;
}

}  // namespace pvr::tcl
