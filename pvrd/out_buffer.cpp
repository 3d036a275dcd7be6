#include "out_buffer.h"

#include <sys/socket.h>
#include <sys/uio.h>

#include <cerrno>
#include <cstring>

namespace pvr::daemon {

void OutBuffer::append(std::span<const std::uint8_t> bytes, double now) {
  if (bytes.empty()) return;
  if (empty()) lastProgress_ = now;
  chunks_.emplace_back(bytes.begin(), bytes.end());
  size_ += bytes.size();
}

bool OutBuffer::flush(int fd, double now, std::string& error) {
  while (!chunks_.empty()) {
    // Several chunks per call: frames relayed one by one are small pieces.
    iovec parts[16];
    int count = 0;
    for (auto it = chunks_.begin(); it != chunks_.end() && count < 16; ++it, ++count) {
      const std::size_t skip = count == 0 ? offset_ : 0;
      parts[count] = {it->data() + skip, it->size() - skip};
    }
    msghdr message{};
    message.msg_iov = parts;
    message.msg_iovlen = std::size_t(count);
    const ssize_t sent = ::sendmsg(fd, &message, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (sent < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK) return true;
      if (errno == EINTR) continue;
      error = std::string("send: ") + std::strerror(errno);
      return false;
    }
    lastProgress_ = now;
    size_ -= std::size_t(sent);
    std::size_t left = std::size_t(sent);
    while (left > 0) {
      const std::size_t inFront = chunks_.front().size() - offset_;
      if (left < inFront) {
        offset_ += left;
        break;
      }
      left -= inFront;
      chunks_.pop_front();
      offset_ = 0;
    }
  }
  return true;
}

}  // namespace pvr::daemon
