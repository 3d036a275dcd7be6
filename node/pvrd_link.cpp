#include "pvrd_link.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>

#include "error.h"

namespace pvr::node {

PvrdLink::PvrdLink(const std::string& host, int port, const std::string& jobSecret) {
  const std::string where = host + ":" + std::to_string(port);
  if (jobSecret.empty())
    throw Error(ErrorCode::kInvalidArgument, std::string(proto::kJobSecretVariable) +
                                                 " is not set (pvrd sets it for the job it launches): cannot "
                                                 "open the secure channel to " + where);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(std::uint16_t(port));
  if (port <= 0 || port > 65535 || ::inet_pton(AF_INET, host.c_str(), &addr.sin_addr) != 1)
    throw Error(ErrorCode::kInvalidArgument, "pvrd address " + where + " is not a numeric IPv4 HOST:PORT");
  fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw Error(ErrorCode::kIo, std::string("socket: ") + std::strerror(errno));
  if (::connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    const int e = errno;
    ::close(fd_);
    fd_ = -1;
    throw Error(ErrorCode::kIo, "cannot connect to " + where + ": " + std::strerror(e));
  }
  const int one = 1;
  ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  open_ = true;

  // The handshake, before any frame: pvrd relays nothing until it is done.
  channel_ = std::make_unique<proto::SecureChannel>(proto::SecureChannel::Role::kClient, jobSecret,
                                                    proto::kConnectBackPurpose);
  flush();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(kHandshakeSeconds);
  while (open_ && !channel_->established()) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0 || !readSome(int(left.count()))) break;
  }
  if (!channel_->established()) {
    const std::string why = channel_->failed() ? "pvrd does not hold this job's secret"
                                               : "no handshake within " + std::to_string(kHandshakeSeconds) + " s";
    close();
    throw Error(ErrorCode::kIo, "secure channel to " + where + ": " + why);
  }
}

PvrdLink::~PvrdLink() { close(); }

void PvrdLink::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  open_ = false;
}

void PvrdLink::flush() {
  const std::vector<std::uint8_t> bytes = channel_->takeOutgoing();
  out_.insert(out_.end(), bytes.begin(), bytes.end());
  writeSome();
  while (blocking_ && open_ && unwritten() > 0) {
    pollfd p{fd_, POLLOUT, 0};
    if (::poll(&p, 1, -1) < 0 && errno != EINTR) open_ = false;
    writeSome();
  }
}

void PvrdLink::stopBlocking() {
  blocking_ = false;
  if (fd_ >= 0) ::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) | O_NONBLOCK);
}

void PvrdLink::writeSome() {
  while (open_ && unwritten() > 0) {
    const ssize_t n = ::send(fd_, out_.data() + outDone_, unwritten(), MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return;
    if (n <= 0) {
      open_ = false;
      return;
    }
    outDone_ += std::size_t(n);
  }
  if (outDone_ == out_.size()) {
    out_.clear();
    outDone_ = 0;
  } else if (outDone_ > (1u << 20)) {  // drop what went out, so out_ holds only what has not
    out_.erase(out_.begin(), out_.begin() + std::ptrdiff_t(outDone_));
    outDone_ = 0;
  }
}

bool PvrdLink::readSome(int timeoutMs) {
  for (;;) {
    pollfd p{fd_, POLLIN, 0};
    const int ready = ::poll(&p, 1, timeoutMs);
    if (ready < 0 && errno == EINTR) continue;
    if (ready == 0) return true;
    if (ready < 0) return open_ = false;
    std::uint8_t buf[64 << 10];
    const ssize_t n = ::read(fd_, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return true;
    if (n <= 0) return open_ = false;
    const auto failure = channel_->receive(std::span(buf, std::size_t(n)));
    flush();  // handshake replies, or the alert that says why we stop
    if (failure) {
      std::fprintf(stderr, "pvr-node: rank 0: %s\n", failure->text.c_str());
      return open_ = false;
    }
    return true;
  }
}

void PvrdLink::sendRaw(std::span<const std::uint8_t> bytes) {
  if (!open_) return;
  if (channel_->send(bytes)) {
    open_ = false;
    return;
  }
  flush();
}

void PvrdLink::send(const proto::Message& m, std::uint32_t id, bool final) {
  if (!open_) return;
  sendRaw(proto::encode(m, id, final ? proto::kFlagFinal : 0));
}

std::optional<proto::Decoded> PvrdLink::next(bool wait) {
  for (;;) {
    if (auto frame = decoder_.pop()) return frame;
    if (decoder_.error()) {
      send(proto::ErrorMessage{decoder_.error()->code, decoder_.error()->text}, 0);
      open_ = false;
      return std::nullopt;
    }
    if (!open_) return std::nullopt;
    const std::vector<std::uint8_t> plain = channel_->takeIncoming();
    if (!plain.empty()) {
      decoder_.feed(plain);
      continue;
    }
    pollfd p{fd_, POLLIN, 0};
    const int ready = ::poll(&p, 1, wait ? -1 : 0);
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) return std::nullopt;
    if (!readSome(0)) return std::nullopt;
  }
}

}  // namespace pvr::node
