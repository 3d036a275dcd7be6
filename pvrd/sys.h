// Thin syscall wrappers: each returns the descriptor or -1 and fills `error`
// with the call and errno text; on failure they close what they opened.
#pragma once

#include <cstdint>
#include <span>
#include <string>

namespace pvr::daemon {

// A TCP socket bound to host:port and listening. `port` 0 picks one; the
// bound port is stored back into it.
int tcpListen(const std::string& host, int& port, std::string& error);
// accept() with CLOEXEC; -1 and error text on failure.
int tcpAccept(int listenFd, std::string& error);

// The numeric IPv4 address this host sends from towards `host` (a name or
// address): getsockname of a UDP socket connected to it, which sends no
// packet. Empty, with error text, when `host` does not resolve to IPv4 or
// no route leads there.
std::string routeSourceAddress(const std::string& host, std::string& error);

// "ADDR:PORT" of the peer of a connected socket, "?" if unknown.
std::string peerName(int fd);

// Writes all bytes; false (with error text) on failure or when the peer stops
// reading for longer than the socket's send timeout.
bool writeAll(int fd, std::span<const std::uint8_t> bytes, std::string& error);
// Sets SO_SNDTIMEO so a stalled reader cannot block a writer for ever.
void setSendTimeout(int fd, double seconds);

// errno as "call: text".
std::string errnoText(const char* call);

// Seconds on the monotonic clock.
double monotonicSeconds();

// One log record on stderr: "<ISO time> session <id>: <event>" (id 0: the
// daemon), every byte of the event outside printable ASCII masked as \xNN
// (client text may hold terminal escapes or line breaks).
void logEvent(std::uint64_t session, const std::string& event);

// `bytes` with non-printable characters masked, at most `max` of them.
std::string printable(std::span<const std::uint8_t> bytes, std::size_t max = 32);

}  // namespace pvr::daemon
