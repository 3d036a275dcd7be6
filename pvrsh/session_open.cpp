// Session::open: connect, Hello and Welcome, the secure channel keyed by
// the shared token when the server asks (docs/protocol.md, "The secure
// channel"), and SessionOpen, which starts the MPI job (docs/protocol.md,
// "The conversation"), printing the server's progress while a batch system
// keeps the job queued.
#include <algorithm>

#include "session.h"
#include "token_file.h"

namespace pvr::tcl {
namespace {

// The shared token of a token file (proto::readTokenFile's rules).
std::string readToken(const std::string& path) {
  auto token = proto::readTokenFile(path);
  if (const auto* refused = std::get_if<proto::TokenFileError>(&token))
    throw TclError({"PVR", "CONNECT", "TOKEN"}, refused->text);
  return std::get<std::string>(token);
}

// A SessionOpen's progress while the job waits for its ranks: one line on
// stderr, "pvr: queued: slurm job 12: Priority", from the StatusReply's
// keys state, batch_job and reason (docs/pvrsh.md).
void printQueueProgress(const proto::Message& m) {
  const auto* reply = std::get_if<proto::StatusReply>(&m);
  if (!reply) return;
  std::string state = "waiting", job, reason;
  for (const auto& kv : reply->entries) {
    if (kv.key == "state") state = kv.value;
    if (kv.key == "batch_job") job = kv.value;
    if (kv.key == "reason") reason = kv.value;
  }
  std::string line = "pvr: " + state;
  if (!job.empty()) line += ": slurm job " + job;
  if (!reason.empty()) line += ": " + reason;
  line += "\n";
  // Through Tcl's stderr channel, so a script (or a test) that redirects
  // the channel sees the line.
  if (Tcl_Channel err = Tcl_GetStdChannel(TCL_STDERR)) {
    Tcl_WriteChars(err, line.data(), int(line.size()));
    Tcl_Flush(err);
  }
}

}  // namespace

void Session::open(const OpenRequest& request) {
  const double timeout = request.timeout;
  if (state_ == State::kOpen || state_ == State::kConnecting)
    throw TclError({"PVR", "STATE", "OPEN"}, "session " + name_ + " is already open to " + peer_ + " (close it first)");
  const std::string token = request.tokenFile.empty() ? std::string() : readToken(request.tokenFile);
  Tcl_Preserve(this);
  try {
    // Step 1: TCP connect on the event loop.
    conn_.reset();
    book_.clear();
    book_.setPeer(request.host + ":" + std::to_string(request.port));
    closeReason_.clear();
    lastFailure_.reset();
    state_ = State::kConnecting;
    peer_ = request.host + ":" + std::to_string(request.port);
    conn_ = std::make_unique<Connection>(*this, request.host, request.port, std::min(timeout, 30.0));
    conn_->setFrameTimeout(timeout);
    runEventsUntil([&] { return !conn_ || conn_->connected() || conn_->failed(); }, timeout);
    if (!conn_ || !conn_->connected()) {
      if (conn_ && !conn_->failed())
        throw TclError({"PVR", "CONNECT", "TIMEOUT"}, "cannot connect to " + peer_ + ": timed out");
      if (lastFailure_) throw *lastFailure_;
      throw TclError({"PVR", "CONNECT", "FAILED"}, "cannot connect to " + peer_);
    }
    // Step 2: Hello, Welcome, and the secure channel when the server asks.
    const auto hello = query(proto::Hello{"pvrsh " PVR_PACKAGE_VERSION}, timeout);
    const auto* welcome = std::get_if<proto::Welcome>(&hello.front());
    if (!welcome) throw TclError({"PVR", "PROTOCOL", "UNEXPECTED_MESSAGE"}, peer_ + " did not answer Hello with Welcome");
    serverSoftware_ = welcome->software;
    maxRanks_ = welcome->maxRanks;
    if (welcome->authRequired && token.empty())
      throw TclError({"PVR", "CONNECT", "TOKEN"}, peer_ + " requires a token: open with -token-file FILE");
    // A client with a token talks only to a server that proves it holds
    // the token too: one that does not ask may be anyone.
    if (!welcome->authRequired && !token.empty())
      throw TclError({"PVR", "AUTH", "NOSERVERAUTH"},
                     peer_ + " does not ask for a token, so it cannot prove it holds yours; not opening a session "
                             "with -token-file to it (open without -token-file if it is a local pvrd without one)");
    // Frames from here on wait in the channel until its handshake is done;
    // SessionOpen's answer then arrives through it.
    if (welcome->authRequired) conn_->startSecure(token);
    // Step 3: start the MPI job with the layout set so far.
    if (request.ranks > 0 && maxRanks_ > 0 && request.ranks > maxRanks_)
      throw TclError({"PVR", "ARGS", "RANKS"}, "-ranks " + std::to_string(request.ranks) + " is more than " + peer_ +
                                                   " allows (" + std::to_string(maxRanks_) + ")");
    // A batch system may hold the job in its queue: each progress report
    // is printed and gives the job another full timeout.
    const auto ready = query(proto::SessionOpen{request.ranks, settings_.clusters, request.account}, std::max(timeout, 120.0),
                             printQueueProgress);
    const auto* r = std::get_if<proto::SessionReady>(&ready.back());
    if (!r) throw TclError({"PVR", "PROTOCOL", "UNEXPECTED_MESSAGE"}, peer_ + " did not answer SessionOpen with SessionReady");
    ranks_ = r->rankCount;
    layout_ = r->clusters;
    state_ = State::kOpen;
    layoutPending_ = false;
    // Step 4: what was set before the session opened.
    // The server holds nothing yet: what it accepts of them is kept.
    forgetSent();
    accepted_ = Settings{};
    accepted_.clusters = settings_.clusters;
    const SettingsChange opening = wholeChange(settings_);
    if (opening.dataset || !opening.patch.empty())
      sendScene(opening);
    else
      accepted_ = settings_;
    settings_.cameraMoves = nlohmann::json::array();
  } catch (...) {
    if (!deleted_) {
      conn_.reset();
      book_.pending.clear();
      state_ = State::kFailed;
    }
    Tcl_Release(this);
    throw;
  }
  Tcl_Release(this);
}

}  // namespace pvr::tcl
