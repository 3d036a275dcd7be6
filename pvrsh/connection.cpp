#include "connection.h"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>

namespace pvr::tcl {

Connection::Connection(Listener& listener, const std::string& host, int port, double timeoutSeconds)
    : listener_(listener), peer_(host + ":" + std::to_string(port)) {
  // Step 1: resolve. Numeric and local names answer at once; a slow DNS
  // lookup is the one place a connection may hold the interpreter.
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  if (const int rc = ::getaddrinfo(host.c_str(), service.c_str(), &hints, &found); rc != 0)
    throw TclError({"PVR", "CONNECT", "RESOLVE"}, "cannot resolve host '" + host + "': " + ::gai_strerror(rc));

  // Step 2: a non-blocking socket and connect; completion arrives as writability.
  int err = 0;
  for (addrinfo* a = found; a && fd_ < 0; a = a->ai_next) {
    const int fd = ::socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) {
      err = errno;
      continue;
    }
    if (::connect(fd, a->ai_addr, a->ai_addrlen) == 0 || errno == EINPROGRESS) {
      fd_ = fd;
    } else {
      err = errno;
      ::close(fd);
    }
  }
  ::freeaddrinfo(found);
  if (fd_ < 0) {
    const bool refused = err == ECONNREFUSED;
    throw TclError({"PVR", "CONNECT", refused ? "REFUSED" : "SOCKET"},
                   "cannot connect to " + peer_ + ": " + std::strerror(err));
  }
  const int one = 1;
  ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  updateMask();
  timer_ = Tcl_CreateTimerHandler(int(timeoutSeconds * 1000), timeoutProc, this);
}

Connection::~Connection() {
  *alive_ = false;
  closeSocket();
}

void Connection::closeSocket() {
  if (timer_) Tcl_DeleteTimerHandler(timer_);
  timer_ = nullptr;
  if (frameTimer_) Tcl_DeleteTimerHandler(frameTimer_);
  frameTimer_ = nullptr;
  if (fd_ >= 0) {
    Tcl_DeleteFileHandler(fd_);
    ::close(fd_);
  }
  fd_ = -1;
  mask_ = 0;
}

void Connection::updateMask() {
  if (fd_ < 0) return;
  int mask = 0;
  if (state_ == State::kConnecting) mask = TCL_WRITABLE;
  if (state_ == State::kConnected) mask = TCL_READABLE | (outDone_ < out_.size() ? TCL_WRITABLE : 0);
  if (mask == mask_) return;
  mask_ = mask;
  Tcl_CreateFileHandler(fd_, mask, fileProc, this);
}

void Connection::fail(std::vector<std::string> code, const std::string& message) {
  if (state_ == State::kFailed) return;
  state_ = State::kFailed;
  closeSocket();
  listener_.onFailure(TclError(std::move(code), message));
}

void Connection::timeoutProc(ClientData data) {
  auto* self = static_cast<Connection*>(data);
  self->timer_ = nullptr;
  if (self->state_ == State::kConnecting)
    self->fail({"PVR", "CONNECT", "TIMEOUT"}, "cannot connect to " + self->peer_ + ": timed out");
}

void Connection::frameTimeoutProc(ClientData data) {
  auto* self = static_cast<Connection*>(data);
  self->frameTimer_ = nullptr;
  char limit[32];
  std::snprintf(limit, sizeof limit, "%g", self->frameTimeout_);
  self->fail({"PVR", "PROTOCOL", "TIMEOUT"}, "protocol error from " + self->peer_ + ": a frame began and its rest did not arrive within " +
                                               limit + " s (the session's -timeout); the session is closed");
}

void Connection::watchFrame() {
  if (state_ != State::kConnected) return;
  // A frame ended since the last look: the one in progress (if any) is new.
  const std::uint64_t ended = intake_.framesEnded();
  if (frameTimer_ && (ended != framesEndedSeen_ || !intake_.inFrame())) {
    Tcl_DeleteTimerHandler(frameTimer_);
    frameTimer_ = nullptr;
  }
  framesEndedSeen_ = ended;
  if (intake_.inFrame() && !frameTimer_)
    frameTimer_ = Tcl_CreateTimerHandler(int(std::min(frameTimeout_, 1e6) * 1000), frameTimeoutProc, this);
}

void Connection::fileProc(ClientData data, int mask) {
  auto* self = static_cast<Connection*>(data);
  const std::shared_ptr<bool> alive = self->alive_;
  if (self->state_ == State::kConnecting) {
    self->finishConnect();
    return;
  }
  if (mask & TCL_WRITABLE) self->writeSome();
  if (*alive && self->state_ == State::kConnected && (mask & TCL_READABLE)) self->readSome();
}

void Connection::finishConnect() {
  int err = 0;
  socklen_t len = sizeof err;
  ::getsockopt(fd_, SOL_SOCKET, SO_ERROR, &err, &len);
  if (err != 0) {
    fail({"PVR", "CONNECT", err == ECONNREFUSED ? "REFUSED" : "SOCKET"},
         "cannot connect to " + peer_ + ": " + std::strerror(err));
    return;
  }
  if (timer_) Tcl_DeleteTimerHandler(timer_);
  timer_ = nullptr;
  state_ = State::kConnected;
  writeSome();  // frames queued while connecting; updates the mask
}

bool Connection::send(const proto::Message& message, std::uint32_t requestId) {
  if (state_ == State::kFailed) return false;
  const std::vector<std::uint8_t> frame = proto::encode(message, requestId, 0);
  if (!channel_) {
    queue(frame);
  } else if (const auto failure = channel_->send(frame)) {
    fail({"PVR", "AUTH", "FAILED"}, "secure channel to " + peer_ + ": " + failure->text);
    return false;
  } else {
    queue(channel_->takeOutgoing());
  }
  if (state_ == State::kConnected) writeSome();
  return state_ != State::kFailed;
}

void Connection::queue(std::span<const std::uint8_t> bytes) {
  if (outDone_ == out_.size()) {
    out_.clear();
    outDone_ = 0;
  }
  out_.insert(out_.end(), bytes.begin(), bytes.end());
}

void Connection::startSecure(const std::string& token) {
  channel_ = std::make_unique<proto::SecureChannel>(proto::SecureChannel::Role::kClient, token,
                                                    proto::kClientPurpose);
  queue(channel_->takeOutgoing());  // the ClientHello
  if (state_ == State::kConnected) writeSome();
}

void Connection::writeSome() {
  while (outDone_ < out_.size()) {
    const ssize_t n = ::send(fd_, out_.data() + outDone_, out_.size() - outDone_, MSG_NOSIGNAL);
    if (n > 0) {
      outDone_ += std::size_t(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
    fail({"PVR", "CONNECT", "LOST"}, "connection to " + peer_ + " lost while sending: " + std::strerror(errno));
    return;
  }
  if (outDone_ == out_.size()) {
    out_.clear();
    outDone_ = 0;
  }
  updateMask();
}

void Connection::readSome() {
  // One read per event: a fast server cannot starve the other handlers.
  std::uint8_t buf[256 << 10];
  const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
  if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) return;
  if (n > 0 && !channel_) intake_.feed(std::span<const std::uint8_t>(buf, std::size_t(n)));
  if (n > 0 && channel_) {
    const auto failure = channel_->receive(std::span<const std::uint8_t>(buf, std::size_t(n)));
    queue(channel_->takeOutgoing());  // handshake replies, or the alert that says why we stop
    writeSome();
    if (state_ != State::kConnected) return;
    if (failure) {
      fail({"PVR", "AUTH", "FAILED"}, "cannot authenticate with " + peer_ + ": " + failure->text);
      return;
    }
    intake_.feed(channel_->takeIncoming());
  }
  const std::shared_ptr<bool> alive = alive_;
  while (auto item = intake_.pop()) {
    if (const auto* message = std::get_if<proto::Decoded>(&*item))
      listener_.onMessage(*message);
    else
      listener_.onRefused(std::get<FrameIntake::Refused>(*item));
    if (!*alive || state_ != State::kConnected) return;
  }
  if (intake_.error()) {
    const auto& e = *intake_.error();
    fail({"PVR", "PROTOCOL", std::string(proto::errorCodeName(e.code))},
         "protocol error from " + peer_ + ": " + e.text);
    return;
  }
  if (n == 0) {
    if (const auto& e = intake_.endOfStream())
      fail({"PVR", "PROTOCOL", std::string(proto::errorCodeName(e->code))},
           "protocol error from " + peer_ + ": " + e->text);
    else
      fail({"PVR", "CONNECT", "LOST"}, "connection to " + peer_ + " closed by the server");
  } else if (n < 0) {
    fail({"PVR", "CONNECT", "LOST"}, "connection to " + peer_ + " lost: " + std::strerror(errno));
  } else {
    watchFrame();
  }
}

}  // namespace pvr::tcl
