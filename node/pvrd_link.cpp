#include "pvrd_link.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "error.h"

namespace pvr::node {

PvrdLink::PvrdLink(const std::string& host, int port) {
  const std::string where = host + ":" + std::to_string(port);
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
}

PvrdLink::~PvrdLink() { close(); }

void PvrdLink::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  open_ = false;
}

void PvrdLink::sendRaw(std::span<const std::uint8_t> bytes) {
  std::size_t done = 0;
  while (open_ && done < bytes.size()) {
    const ssize_t n = ::send(fd_, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      open_ = false;
      return;
    }
    done += std::size_t(n);
  }
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
    pollfd p{fd_, POLLIN, 0};
    const int ready = ::poll(&p, 1, wait ? -1 : 0);
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) return std::nullopt;
    std::uint8_t buf[64 << 10];
    const ssize_t n = ::read(fd_, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      open_ = false;
      return std::nullopt;
    }
    decoder_.feed(std::span(buf, std::size_t(n)));
  }
}

}  // namespace pvr::node
