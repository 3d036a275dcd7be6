#include "session.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <deque>
#include <memory>
#include <optional>
#include <set>

#include "admission.h"
#include "auth.h"
#include "catalog.h"
#include "dataset_names.h"
#include "connect_back.h"
#include "launcher.h"
#include "out_buffer.h"
#include "pvr_protocol.h"
#include "sys.h"

namespace pvr::daemon {
namespace {

using proto::ErrorCode;

volatile sig_atomic_t gStop = 0;
void onStop(int) { gStop = 1; }

// The master rank must connect back this soon after its ranks have hosts
// (after the launch for mpirun, after the grant for a batch allocation).
constexpr double kMasterConnectSeconds = 60;
// The most bytes a client may send before its Hello is complete: one
// control frame (Hello) and its header.
constexpr std::size_t kMaxBeforeHello = proto::kHeaderBytes + proto::Limits{}.maxControlPayload;
// How long a job's end waits for the launcher to exit and say why.
constexpr double kLauncherEndSeconds = 5;
// While more than this waits for the client, the master's socket is not
// read: the job slows to the client's pace (one more read and one frame
// being relayed come on top).
constexpr std::size_t kClientBufferBytes = 16u << 20;
// Requests that may wait for the master (before it connects, or while it
// does not read): beyond it a request is refused, not buffered. Requests
// are control frames and scenes (up to 4 MiB): a few of the largest, or
// thousands of the usual ones. One request always fits.
constexpr std::size_t kMasterBufferBytes = 16u << 20;
// How long the last words to a leaving client (its Error, the Close) may
// take to go out.
constexpr double kFarewellSeconds = 1;

void setNonBlocking(int fd) { ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK); }

class Session {
 public:
  Session(const SessionConfig& c, int fd) : cfg_(c), opt_(*c.options), client_(fd), admission_(c.admission) {}
  int run();

 private:
  void log(const std::string& event) const { logEvent(cfg_.id, event); }
  bool sendClient(const proto::Message& m, std::uint32_t id, bool final = true);
  bool sendClientBytes(std::span<const std::uint8_t> frame);
  // Queues bytes for the client's socket as they are (ciphertext, or
  // frames before the secure channel) and writes what it takes now.
  bool writeClient(std::span<const std::uint8_t> bytes);
  // Writes what waits for the client; false when it is gone.
  bool flushClient();
  // The client's last words (an Error, the Close) before the handler ends.
  void farewell();
  void markAuthenticated(const std::string& how);
  // The plaintext in bytes the client's socket gave: through the secure
  // channel once it runs. nullopt when the channel refused them (the
  // connection is then over).
  std::optional<std::vector<std::uint8_t>> clientPlaintext(std::span<const std::uint8_t> bytes);
  void replyError(ErrorCode code, const std::string& text, std::uint32_t id) {
    sendClient(proto::ErrorMessage{code, text}, id);
  }
  void endConnection(ErrorCode code, const std::string& text, std::uint32_t id);
  void onClient(proto::Decoded frame);
  void openSession(const proto::SessionOpen& open, std::uint32_t id);
  // A dataset named by its catalog stem: the real path of the entry's file,
  // or kDatasetNotFound suggesting the closest names (dataset_names.h).
  std::variant<std::string, proto::ProtocolError> resolveStem(const std::string& name);
  void onMaster(proto::RelayItem item);
  // Plaintext for the master, through its secure channel.
  void writeMaster(std::span<const std::uint8_t> plain);
  // What the master's socket gave: decrypted, then relayed.
  void onMasterCiphertext(std::span<const std::uint8_t> bytes);
  void onMasterBytes(std::span<const std::uint8_t> bytes);
  void adoptMaster(ConnectBack::Master master, double now);
  void refuseMasterFrame(const proto::RefusedFrame& refused);
  void forward(const proto::Message& m, std::uint32_t id);
  void flushMaster();
  bool launch(std::uint32_t ranks, const std::string& account, std::string& error);
  void onLaunchEvent(const LaunchEvent& event, double now);
  proto::StatusReply queuedStatus() const;
  void jobEnded(const std::string& why);
  void teardown();

  const SessionConfig& cfg_;
  const DaemonOptions& opt_;
  int client_;
  AdmissionLink admission_;
  bool holdsSlot_ = false;
  OutBuffer toClient_, toMaster_;
  // With a token: every byte after Welcome travels in this channel keyed by
  // the token (docs/protocol.md, "The secure channel").
  std::unique_ptr<proto::SecureChannel> clientChannel_;
  int master_ = -1;
  std::unique_ptr<proto::SecureChannel> masterChannel_;  // with master_: every byte to and from it
  // When the master last sent anything (its Heartbeat comes every 2 s,
  // from a thread no work of its blocks): the job's ranks watch each other,
  // but only the handler can see rank 0 itself stop.
  double lastFromMaster_ = 0;
  std::unique_ptr<Launcher> launcher_;       // while a job runs
  std::unique_ptr<ConnectBack> connectBack_;  // until the master proved itself
  double masterDeadline_ = 0;                // 0: none (waiting in a batch queue)
  // The SessionOpen not answered yet: queue progress and a failed launch answer it.
  std::uint32_t openRequest_ = 0;
  std::optional<LaunchEvent> queued_;  // the allocation request waits in a batch queue
  proto::FrameDecoder fromClient_;
  // Master frames are checked and passed on as they came, not re-encoded.
  proto::FrameRelay fromMaster_;
  // Requests answered with an Error after pvrd refused a master frame: the
  // master's further frames for them are dropped until its FINAL one.
  std::set<std::uint32_t> refusedRequests_;
  // Render requests sent to the master whose FINAL frame has not come back:
  // while one is in flight the client waits for us, it is not idle.
  std::set<std::uint32_t> rendering_;
  bool greeted_ = false, authenticated_ = false, done_ = false;
  // Plaintext for the master before it connected (bytes in all: pendingBytes_).
  std::deque<std::vector<std::uint8_t>> pendingToMaster_;
  std::size_t pendingBytes_ = 0;
  double launchedAt_ = 0;
  std::string masterPeer_;  // "ADDR:PORT" of the master's connection
};

bool Session::sendClient(const proto::Message& m, std::uint32_t id, bool final) {
  return sendClientBytes(proto::encode(m, id, final ? proto::kFlagFinal : 0));
}

bool Session::sendClientBytes(std::span<const std::uint8_t> frame) {
  if (client_ < 0) return false;
  if (!clientChannel_) return writeClient(frame);
  if (auto failure = clientChannel_->send(frame)) {
    log("client: " + failure->text);
    done_ = true;
    return false;
  }
  return writeClient(clientChannel_->takeOutgoing());
}

std::optional<std::vector<std::uint8_t>> Session::clientPlaintext(std::span<const std::uint8_t> bytes) {
  if (!clientChannel_) return std::vector<std::uint8_t>(bytes.begin(), bytes.end());
  const auto failure = clientChannel_->receive(bytes);
  // Handshake replies, or the alert that tells the client why we stop.
  writeClient(clientChannel_->takeOutgoing());
  if (failure) {
    log("refused the client: " + failure->text);
    done_ = true;
    return std::nullopt;
  }
  if (!authenticated_ && clientChannel_->established()) markAuthenticated("authenticated (secure channel)");
  return clientChannel_->takeIncoming();
}

void Session::markAuthenticated(const std::string& how) {
  authenticated_ = true;
  admission_.authenticated();
  log(how);
}

bool Session::writeClient(std::span<const std::uint8_t> bytes) {
  if (client_ < 0) return false;
  toClient_.append(bytes, monotonicSeconds());
  return flushClient();
}

bool Session::flushClient() {
  if (client_ < 0) return false;
  std::string error;
  if (toClient_.flush(client_, monotonicSeconds(), error)) return true;
  log("client write failed: " + error);
  ::close(client_);
  client_ = -1;
  done_ = true;
  return false;
}

void Session::farewell() {
  const double until = monotonicSeconds() + kFarewellSeconds;
  while (client_ >= 0 && !toClient_.empty() && monotonicSeconds() < until) {
    pollfd p{client_, POLLOUT, 0};
    if (::poll(&p, 1, 50) < 0 && errno != EINTR) break;
    if (!flushClient()) break;
  }
}

void Session::endConnection(ErrorCode code, const std::string& text, std::uint32_t id) {
  log("closing: " + std::string(proto::errorCodeName(code)) + ": " + text);
  replyError(code, text, id);
  sendClient(proto::Close{text}, 0);
  done_ = true;
}

void Session::forward(const proto::Message& m, std::uint32_t id) {
  auto bytes = proto::encode(m, id, 0);
  // A job that does not take its requests gets no more of them: the
  // client hears why instead of the handler's memory growing.
  const std::size_t waiting = master_ < 0 ? pendingBytes_ : toMaster_.size();
  if (waiting > 0 && waiting + bytes.size() > kMasterBufferBytes && !std::holds_alternative<proto::Close>(m)) {
    if (rendering_.erase(id)) log("refused request " + std::to_string(id) + ": the job is not taking requests");
    return replyError(ErrorCode::kLimitExceeded,
                      std::to_string(waiting) + " bytes of requests already wait for the rendering job " +
                          (master_ < 0 ? "to connect" : "to read them") + "; this one is dropped",
                      id);
  }
  if (master_ < 0) {
    pendingBytes_ += bytes.size();
    pendingToMaster_.push_back(std::move(bytes));
    return;
  }
  writeMaster(bytes);
}

void Session::writeMaster(std::span<const std::uint8_t> plain) {
  if (auto failure = masterChannel_->send(plain)) return jobEnded("secure channel to the master: " + failure->text);
  toMaster_.append(masterChannel_->takeOutgoing(), monotonicSeconds());
  flushMaster();
}

void Session::flushMaster() {
  std::string error;
  if (master_ >= 0 && !toMaster_.flush(master_, monotonicSeconds(), error)) jobEnded("master write failed: " + error);
}

void Session::onMasterCiphertext(std::span<const std::uint8_t> bytes) {
  const auto failure = masterChannel_->receive(bytes);
  toMaster_.append(masterChannel_->takeOutgoing(), monotonicSeconds());
  flushMaster();
  if (done_) return;
  if (failure) return jobEnded("secure channel to the master: " + failure->text);
  const std::vector<std::uint8_t> plain = masterChannel_->takeIncoming();
  if (!plain.empty()) onMasterBytes(plain);
}

void Session::onClient(proto::Decoded frame) {
  const std::uint32_t id = frame.info.requestId;
  const proto::Message& m = frame.message;
  if (std::holds_alternative<proto::Close>(m)) {
    log("client sent Close");
    if (master_ >= 0) forward(m, id);
    sendClient(proto::Close{"bye"}, 0);
    done_ = true;
    return;
  }
  if (!greeted_) {
    if (!std::holds_alternative<proto::Hello>(m)) return endConnection(ErrorCode::kUnexpectedMessage, "expected Hello", id);
    greeted_ = true;
    log("hello from '" + std::get<proto::Hello>(m).software + "'");
    const bool auth = !cfg_.token.empty();
    sendClient(proto::Welcome{"pvrd 0.1", std::uint32_t(opt_.maxRanks), auth}, id);
    // With a token the secure channel starts now: the next bytes are the
    // client's TLS handshake, and frames arrive only once it has proved
    // the token (clientPlaintext).
    if (auth)
      clientChannel_ = std::make_unique<proto::SecureChannel>(proto::SecureChannel::Role::kServer, cfg_.token,
                                                              proto::kClientPurpose);
    else
      markAuthenticated("no token: the Hello admits the client");
    return;
  }
  if (!authenticated_) return endConnection(ErrorCode::kUnexpectedMessage, "authenticate first", id);
  if (std::holds_alternative<proto::JobHello>(m))
    return replyError(ErrorCode::kUnexpectedMessage, "JobHello is the rendering job's message, not a client's", id);
  if (std::holds_alternative<proto::CatalogRequest>(m)) {
    // The node program knows the formats (catalog.h); a failure is the
    // client's Error and this session serves on.
    auto listed = listDatasets(cfg_.nodePath, opt_.dataDir, kCatalogSeconds,
                               [this](const std::string& note) { log("catalog: " + note); });
    if (const auto* err = std::get_if<proto::ProtocolError>(&listed)) {
      log(err->text);
      return replyError(err->code, err->text, id);
    }
    sendClient(proto::CatalogReply{std::move(std::get<std::vector<proto::CatalogEntry>>(listed))}, id);
    return;
  }
  if (const auto* open = std::get_if<proto::SessionOpen>(&m)) return openSession(*open, id);
  if (std::holds_alternative<proto::StatusRequest>(m) && (!launcher_ || queued_)) {
    sendClient(launcher_ ? queuedStatus() : proto::StatusReply{{{"state", "connected"}, {"session", "none"}}}, id);
    return;
  }
  if (!launcher_) return replyError(ErrorCode::kUnexpectedMessage, "open a session first", id);
  if (const auto* scene = std::get_if<proto::SetScene>(&m); scene && !scene->dataset.empty()) {
    auto resolved = resolveDataset(opt_.dataDir, scene->dataset);
    if (auto* err = std::get_if<proto::ProtocolError>(&resolved); err && err->code == ErrorCode::kDatasetNotFound)
      resolved = resolveStem(scene->dataset);
    if (auto* err = std::get_if<proto::ProtocolError>(&resolved)) {
      log("refused dataset '" + scene->dataset + "': " + err->text);
      return replyError(err->code, err->text, id);
    }
    return forward(proto::SetScene{std::get<std::string>(resolved), scene->sceneJson}, id);
  }
  if (proto::isRenderRequest(m)) rendering_.insert(id);
  forward(m, id);
}

std::variant<std::string, proto::ProtocolError> Session::resolveStem(const std::string& name) {
  auto listed = listDatasets(cfg_.nodePath, opt_.dataDir, kCatalogSeconds,
                             [this](const std::string& note) { log("catalog: " + note); });
  if (auto* err = std::get_if<proto::ProtocolError>(&listed)) return *err;
  const auto& catalog = std::get<std::vector<proto::CatalogEntry>>(listed);
  if (const auto file = fileOfStem(catalog, name)) return resolveDataset(opt_.dataDir, *file);
  return proto::ProtocolError{ErrorCode::kDatasetNotFound, unknownDatasetText(name, catalog)};
}

void Session::openSession(const proto::SessionOpen& open, std::uint32_t id) {
  if (launcher_) return replyError(ErrorCode::kUnexpectedMessage, "a session is already open", id);
  const std::uint32_t ranks = open.rankCount ? open.rankCount : std::uint32_t(std::min(2, opt_.maxRanks));
  if (ranks > std::uint32_t(opt_.maxRanks))
    return replyError(ErrorCode::kLimitExceeded,
                      "ranks " + std::to_string(ranks) + " over --max-ranks " + std::to_string(opt_.maxRanks), id);
  if (!isValidAccount(open.account))
    return replyError(ErrorCode::kBadArgument,
                      "account '" + printable(std::span(reinterpret_cast<const std::uint8_t*>(open.account.data()),
                                                        open.account.size())) +
                          "' may hold only A-Z a-z 0-9 _ . -",
                      id);
  // The slot is the daemon's to give (admission.h); without one the
  // client stays connected and may try again.
  if (auto refused = admission_.requestSlot(opt_.maxSessions)) {
    log("SessionOpen refused: " + *refused);
    return replyError(ErrorCode::kLimitExceeded, *refused, id);
  }
  holdsSlot_ = true;
  std::string error;
  if (!launch(ranks, open.account, error)) {
    teardown();
    return replyError(ErrorCode::kInternal, "cannot start the job: " + error, id);
  }
  openRequest_ = id;
  forward(open, id);
}

void Session::onMaster(proto::RelayItem item) {
  if (const auto* refused = std::get_if<proto::RefusedFrame>(&item)) return refuseMasterFrame(*refused);
  const auto& frame = std::get<proto::RelayedFrame>(item);
  if (frame.header.type == proto::Close::kWire.type) return jobEnded("the master closed the session");
  // A JobHello is for the handler alone; relayed, it would show a client the secret.
  if (frame.header.type == proto::JobHello::kWire.type) return log("dropped a second JobHello from the master");
  // The master's sign of life is for the handler alone too.
  if (frame.header.type == proto::Heartbeat::kWire.type) return;
  const std::uint32_t id = frame.header.requestId;
  const bool final = (frame.header.flags & proto::kFlagFinal) != 0;
  if (final && id == openRequest_) openRequest_ = 0;
  if (final) rendering_.erase(id);
  if (refusedRequests_.count(id)) {
    // The client already has its Error for this request.
    if (final) refusedRequests_.erase(id);
    return;
  }
  sendClientBytes(frame.bytes);
}

void Session::onMasterBytes(std::span<const std::uint8_t> bytes) {
  fromMaster_.feed(bytes);
  while (auto item = fromMaster_.pop()) {
    onMaster(std::move(*item));
    if (done_) return;
  }
  if (fromMaster_.error()) jobEnded("bad frame from the master: " + fromMaster_.error()->text);
}

void Session::refuseMasterFrame(const proto::RefusedFrame& refused) {
  const std::uint32_t id = refused.header.requestId;
  const bool final = (refused.header.flags & proto::kFlagFinal) != 0;
  if (final && id == openRequest_) openRequest_ = 0;
  if (final) rendering_.erase(id);
  const std::string what = "the rendering job's " + std::string(refused.info->name);
  log("refused " + what + " for request " + std::to_string(id) + ": " + refused.error.text);
  if (refusedRequests_.count(id)) {
    if (final) refusedRequests_.erase(id);
    return;
  }
  // The session goes on: the frame's end was known, the stream is intact.
  replyError(refused.error.code, "pvrd refused " + what + ": " + refused.error.text, id);
  if (!final && id != 0) refusedRequests_.insert(id);
}

void Session::adoptMaster(ConnectBack::Master master, double now) {
  master_ = master.fd;
  masterPeer_ = master.peer;
  lastFromMaster_ = now;
  setNonBlocking(master_);
  masterChannel_ = std::move(master.channel);
  connectBack_.reset();
  masterDeadline_ = 0;
  log("master connected from " + master.peer + " after " + std::to_string(now - launchedAt_) + " s");
  while (!pendingToMaster_.empty() && !done_) {
    writeMaster(pendingToMaster_.front());
    pendingToMaster_.pop_front();
  }
  pendingBytes_ = 0;
  if (!done_ && !master.rest.empty()) onMasterBytes(master.rest);
}

bool Session::launch(std::uint32_t ranks, const std::string& account, std::string& error) {
  const auto secret = makeJobSecret();
  if (!secret) {
    error = "no random secret";
    return false;
  }
  connectBack_ = std::make_unique<ConnectBack>(cfg_.id, *secret);
  if (!connectBack_->listen(cfg_.advertise, error)) return false;
  JobSpec spec{ranks,
               cfg_.nodePath,
               connectBack_->where(),
               opt_.dataDir,
               *secret,
               account,
               "pvr-" + std::to_string(cfg_.daemonPid) + "-" + std::to_string(cfg_.id),
               cfg_.id};
  launcher_ = makeLauncher(opt_);
  if (!launcher_->start(spec, error)) return false;
  launchedAt_ = monotonicSeconds();
  masterDeadline_ = launchedAt_ + kMasterConnectSeconds;
  log("launched " + std::string(launcher_->program()) + " pid " + std::to_string(launcher_->pid()) + " with " +
      std::to_string(ranks) + " ranks, master connects back to " + connectBack_->where() +
      (account.empty() ? "" : ", account " + account));
  return true;
}

proto::StatusReply Session::queuedStatus() const {
  return proto::StatusReply{{{"state", "queued"}, {"batch_job", queued_->batchJob}, {"reason", queued_->reason}}};
}

void Session::onLaunchEvent(const LaunchEvent& event, double now) {
  switch (event.kind) {
    case LaunchEvent::Kind::kQueued:
      // The wait for an allocation has no time limit; the client sees it.
      queued_ = event;
      masterDeadline_ = 0;
      log("queued: batch job " + event.batchJob + ": " + event.reason);
      if (openRequest_) sendClient(queuedStatus(), openRequest_, false);
      return;
    case LaunchEvent::Kind::kGranted:
      if (queued_ || masterDeadline_ == 0) log("allocation " + event.batchJob + " granted");
      queued_.reset();
      if (master_ < 0) masterDeadline_ = now + kMasterConnectSeconds;
      return;
    case LaunchEvent::Kind::kLost:
      return jobEnded(event.reason);
  }
}

void Session::jobEnded(const std::string& why) {
  if (done_) return;
  // Give the launcher time to print which rank or host failed and exit:
  // after a lost host mpirun first prints a generic block about daemons and
  // names the host only when it gives up on it, which took over a second
  // in one run of five (tests/cluster/host_lost.sh).
  const double until = monotonicSeconds() + kLauncherEndSeconds;
  while (launcher_ && monotonicSeconds() < until && !launcher_->exited()) {
    launcher_->readOutput();
    ::usleep(20000);
  }
  std::string text = why;
  if (launcher_) {
    launcher_->readOutput();
    text = launcher_->endText(why);
  }
  log("job ended: " + text);
  const std::uint32_t id = openRequest_;
  teardown();
  replyError(ErrorCode::kRankFailed, text, id);
  sendClient(proto::Close{"the rendering job ended"}, 0);
  done_ = true;
}

void Session::teardown() {
  if (master_ >= 0) ::close(std::exchange(master_, -1));
  connectBack_.reset();
  queued_.reset();
  rendering_.clear();
  openRequest_ = 0;
  masterDeadline_ = 0;
  toMaster_ = OutBuffer{};
  pendingToMaster_.clear();
  pendingBytes_ = 0;
  if (holdsSlot_) admission_.releaseSlot();
  holdsSlot_ = false;
  if (!launcher_) return;
  const double t0 = monotonicSeconds();
  const pid_t pid = launcher_->pid();
  launcher_->stop();
  launcher_.reset();
  log("job " + std::to_string(pid) + " gone after " + std::to_string(monotonicSeconds() - t0) + " s");
}

int Session::run() {
  setNonBlocking(client_);
  const double acceptedAt = monotonicSeconds();
  double lastFrame = acceptedAt;
  double frameStarted = 0;
  std::vector<std::uint8_t> buf(64 << 10);
  std::vector<pollfd> fds;
  while (!done_ && !gStop) {
    // Poll the client, the master, the job's output, the connect-back. The
    // client is always read, so its leaving is seen at once; the master is
    // not read while its frames wait for a slow client.
    fds.clear();
    const std::size_t ci = fds.size();
    if (client_ >= 0) fds.push_back({client_, short(POLLIN | (toClient_.empty() ? 0 : POLLOUT)), 0});
    const std::size_t mi = fds.size();
    if (master_ >= 0) {
      const bool take = toClient_.size() <= kClientBufferBytes;
      // Not reading the master is our doing, not its silence.
      if (!take) lastFromMaster_ = monotonicSeconds();
      fds.push_back({master_, short((take ? POLLIN : 0) | (toMaster_.empty() ? 0 : POLLOUT)), 0});
    }
    const std::size_t oi = fds.size();
    if (launcher_ && launcher_->outputFd() >= 0) fds.push_back({launcher_->outputFd(), POLLIN, 0});
    const std::size_t bi = fds.size();
    if (connectBack_) {
      const auto more = connectBack_->pollFds();
      fds.insert(fds.end(), more.begin(), more.end());
    }
    const auto ready = [&](std::size_t i, std::size_t next) {
      return i < next && (fds[i].revents & (POLLIN | POLLHUP | POLLERR));
    };
    const auto writable = [&](std::size_t i, std::size_t next) { return i < next && (fds[i].revents & POLLOUT); };
    if (::poll(fds.data(), nfds_t(fds.size()), 100) < 0 && errno != EINTR) {
      log(errnoText("poll"));
      break;
    }
    const double now = monotonicSeconds();

    if (writable(ci, mi) && !flushClient()) break;
    if (writable(mi, oi)) {
      flushMaster();
      if (done_) break;
    }

    // The client: requests, the end of its stream, a stalled frame, idleness.
    if (ready(ci, mi)) {
      const ssize_t got = ::read(client_, buf.data(), buf.size());
      if (got < 0 && (errno == EAGAIN || errno == EINTR)) continue;
      if (got <= 0) {
        // A frame left unfinished gets its error, in case the client still reads.
        if (const auto& e = fromClient_.endOfStream()) endConnection(e->code, e->text, 0);
        log("client disconnected");
        done_ = true;
        break;
      }
      const std::size_t before = fromClient_.bufferedBytes();
      const auto plain = clientPlaintext(std::span(buf.data(), std::size_t(got)));
      if (!plain) break;
      const bool secure = clientChannel_ != nullptr;
      fromClient_.feed(*plain);
      bool completed = false;
      while (auto frame = fromClient_.pop()) {
        lastFrame = now;
        completed = true;
        onClient(std::move(*frame));
        if (done_) break;
        // Hello started the secure channel: nothing may follow it in the clear.
        if (!secure && clientChannel_ && (fromClient_.bufferedBytes() > 0 || fromClient_.pop())) {
          log("refused the client: bytes after Hello in the clear, where the secure channel starts");
          done_ = true;
          break;
        }
      }
      if (done_) break;
      if (const auto& e = fromClient_.error()) {
        log("bad frame from client, first bytes '" + printable(std::span(buf.data(), std::size_t(got))) + "'");
        endConnection(e->code, e->text, 0);
        break;
      }
      // Before Hello only a Hello may come, and a Hello is a control frame:
      // buffering more for a stranger (up to the 64 MiB an image frame may
      // have) is what a flood of connections would use to exhaust memory.
      if (!greeted_ && fromClient_.bufferedBytes() > kMaxBeforeHello) {
        endConnection(ErrorCode::kLimitExceeded,
                      "more than " + std::to_string(kMaxBeforeHello) + " bytes before Hello", 0);
        break;
      }
      // The timer runs from the start of the frame in progress: a frame
      // completed in this read means the bytes left began a new one (a
      // client streaming frames back to back never empties the buffer).
      if (fromClient_.bufferedBytes() == 0) frameStarted = 0;
      else if (before == 0 || frameStarted == 0 || completed) frameStarted = now;
    }
    // A stranger has a short while to show who it is (admission.h): it
    // holds one of the few handshake places until then.
    if (!authenticated_ && now - acceptedAt > opt_.handshakeTimeout) {
      const std::string text =
          "no authenticated Hello within " + std::to_string(int(opt_.handshakeTimeout)) + " s (--handshake-timeout)";
      // Inside an unfinished secure channel no frame can be sent: just close.
      if (clientChannel_) {
        log("closing: " + text);
        done_ = true;
      } else {
        endConnection(ErrorCode::kTimeout, text, 0);
      }
      break;
    }
    if (frameStarted > 0 && now - frameStarted > opt_.frameTimeout) {
      endConnection(ErrorCode::kTimeout, "the rest of a started frame did not arrive in time", 0);
      break;
    }
    // A client that takes nothing of what waits for it (not a slow one: a
    // stopped one) cannot be told why; it is let go.
    if (toClient_.stalledFor(now) > opt_.frameTimeout) {
      log("closing: the client read nothing of " + std::to_string(toClient_.size()) + " waiting bytes for " +
          std::to_string(int(opt_.frameTimeout)) + " s");
      done_ = true;
      break;
    }
    // A client waiting for its allocation, for its job to start, or for
    // frames it asked for, is not idle.
    if (queued_ || openRequest_ != 0 || !rendering_.empty()) lastFrame = now;
    if (now - lastFrame > opt_.idleTimeout) {
      endConnection(ErrorCode::kTimeout, "idle for " + std::to_string(int(opt_.idleTimeout)) + " s", 0);
      break;
    }

    // The job's output: queue progress, grants, a lost allocation.
    if (ready(oi, bi) && launcher_) {
      for (const LaunchEvent& e : launcher_->readOutput()) {
        onLaunchEvent(e, now);
        if (done_) break;
      }
      if (done_) break;
    }

    // The connect-back: the master once it shows the secret.
    if (connectBack_ && fds.size() > bi) {
      if (auto master = connectBack_->serve(std::span(fds).subspan(bi), now)) {
        adoptMaster(std::move(*master), now);
        continue;
      }
    }

    // The master's frames, relayed.
    if (ready(mi, oi)) {
      const ssize_t got = ::read(master_, buf.data(), buf.size());
      if (got < 0 && (errno == EAGAIN || errno == EINTR)) continue;
      if (got <= 0) {
        jobEnded("the master rank's connection closed");
        break;
      }
      lastFromMaster_ = now;
      onMasterCiphertext(std::span(buf.data(), std::size_t(got)));
    }
    if (master_ >= 0 && !done_ && now - lastFromMaster_ > opt_.stallTimeout) {
      const std::string host = masterPeer_.substr(0, masterPeer_.rfind(':'));
      jobEnded("rank 0 on " + host + " sent nothing, not even its heartbeat, for " +
               std::to_string(opt_.stallTimeout) + " s (stopped or hung); the job ends");
      break;
    }
    if (launcher_ && !done_ && launcher_->exited()) jobEnded(launcher_->exitText());
    if (launcher_ && !done_ && master_ < 0 && masterDeadline_ > 0 && now > masterDeadline_)
      jobEnded("the master rank did not connect within " + std::to_string(int(kMasterConnectSeconds)) + " s");
  }
  if (gStop) {
    log("stopping on signal");
    sendClient(proto::Close{"pvrd is shutting down"}, 0);
  }
  teardown();
  farewell();
  if (client_ >= 0) ::close(client_);
  log("session ended");
  return 0;
}

}  // namespace

int runSession(const SessionConfig& config, int clientFd) {
  struct sigaction sa {};
  sa.sa_handler = onStop;
  ::sigaction(SIGTERM, &sa, nullptr);
  ::sigaction(SIGINT, &sa, nullptr);
  ::signal(SIGPIPE, SIG_IGN);
  ::signal(SIGCHLD, SIG_DFL);
  ::prctl(PR_SET_PDEATHSIG, SIGTERM);
  for (int fd : config.inherited) ::close(fd);
  Session session(config, clientFd);
  return session.run();
}

}  // namespace pvr::daemon
