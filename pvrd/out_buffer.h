// Bytes on their way to a peer through a non-blocking socket. The session
// handler never blocks on one peer: what the socket does not take now waits
// here, the poll loop writes it when the socket is writable, and the handler
// stops taking more for that peer (it stops reading the other side, or
// refuses the request) once the buffer holds its limit. The time since the
// last byte went out tells a peer that stopped reading from a slow one.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <span>
#include <string>
#include <vector>

namespace pvr::daemon {

class OutBuffer {
 public:
  void append(std::span<const std::uint8_t> bytes, double now);
  // Writes what the socket takes now. False, with error text, when the
  // peer is gone; true when the rest must wait for POLLOUT.
  bool flush(int fd, double now, std::string& error);
  bool empty() const { return size_ == 0; }
  std::size_t size() const { return size_; }
  // Seconds bytes have waited without one of them going out; 0 when empty.
  double stalledFor(double now) const { return empty() ? 0 : now - lastProgress_; }

 private:
  std::deque<std::vector<std::uint8_t>> chunks_;
  std::size_t offset_ = 0;  // bytes of the front chunk already written
  std::size_t size_ = 0;    // bytes waiting
  double lastProgress_ = 0;
};

}  // namespace pvr::daemon
