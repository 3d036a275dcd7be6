// The daemon's ledger of connections (admission.h) and the handler's
// non-blocking output (out_buffer.h).
#include <catch2/catch.hpp>

#include <sys/socket.h>
#include <unistd.h>

#include "admission.h"
#include "out_buffer.h"

using namespace pvr::daemon;

TEST_CASE("admission: strangers have their own limit, a slot is taken at SessionOpen and freed by its end or the handler's") {
  Admission a({2, 4, 1});
  CHECK_FALSE(a.refusalAtAccept());
  a.add(10);
  a.add(11);
  REQUIRE(a.refusalAtAccept());
  CHECK(*a.refusalAtAccept() == "too many connections in handshake (2 of --max-unauthenticated 2); try again shortly");
  CHECK(a.requestSlot(10) == "authenticate first");
  a.authenticated(10);
  a.authenticated(11);
  CHECK(a.handshakes() == 0);
  a.add(12);
  a.add(13);
  a.authenticated(13);
  CHECK(*a.refusalAtAccept() == "too many connections (4 of --max-connections 4)");
  CHECK_FALSE(a.requestSlot(10));
  CHECK_FALSE(a.requestSlot(10));  // asking again holds the same slot
  CHECK(a.sessions() == 1);
  a.authenticated(12);
  REQUIRE(a.requestSlot(11));
  CHECK(*a.requestSlot(11) == "too many sessions: all 1 of --max-sessions are open; try again when one ends");
  a.releaseSlot(10);
  CHECK_FALSE(a.requestSlot(11));
  a.remove(11);
  CHECK(a.sessions() == 0);
  CHECK_FALSE(a.requestSlot(12));
  a.remove(13);
  CHECK(a.connections() == 2);
  CHECK_FALSE(a.refusalAtAccept());
}

TEST_CASE("out buffer: what a socket does not take waits, goes out as the peer reads, and a gone peer is an error") {
  int pair[2];
  REQUIRE(::socketpair(AF_UNIX, SOCK_STREAM, 0, pair) == 0);
  OutBuffer out;
  std::vector<std::uint8_t> bytes(8 << 20);
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = std::uint8_t(i * 7);
  out.append(bytes, 1.0);
  std::string error;
  REQUIRE(out.flush(pair[0], 1.0, error));  // never blocks
  REQUIRE_FALSE(out.empty());
  CHECK(out.size() < bytes.size());
  CHECK(out.stalledFor(4.0) == 3.0);
  // The peer reads everything, in order.
  std::vector<std::uint8_t> got;
  std::vector<std::uint8_t> chunk(1 << 16);
  while (got.size() < bytes.size()) {
    REQUIRE(out.flush(pair[0], 5.0, error));
    const ssize_t n = ::recv(pair[1], chunk.data(), chunk.size(), MSG_DONTWAIT);
    if (n > 0) got.insert(got.end(), chunk.begin(), chunk.begin() + n);
  }
  CHECK(got == bytes);
  CHECK(out.empty());
  CHECK(out.stalledFor(9.0) == 0);
  ::close(pair[1]);
  out.append(bytes, 6.0);
  CHECK_FALSE(out.flush(pair[0], 6.0, error));
  CHECK(error.find("send: ") == 0);
  ::close(pair[0]);
}
