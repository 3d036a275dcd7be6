// SecureChannel between two ends in memory: what passes, and what fails
// (a wrong secret, altered bytes, a replayed record, a relay in the middle).
#include <catch2/catch.hpp>

#include <cstdint>
#include <algorithm>
#include <numeric>
#include <string>
#include <vector>

#include "secure_channel.h"

using pvr::proto::ErrorCode;
using pvr::proto::ProtocolError;
using pvr::proto::SecureChannel;
using Catch::Contains;
using Bytes = std::vector<std::uint8_t>;

namespace {

Bytes bytesOf(const std::string& s) { return Bytes(s.begin(), s.end()); }

// Moves whatever each end has for the other until neither has anything;
// the first error either end reports, if any.
std::optional<ProtocolError> shuttle(SecureChannel& a, SecureChannel& b) {
  for (int round = 0; round < 16; ++round) {
    const Bytes ab = a.takeOutgoing(), ba = b.takeOutgoing();
    if (ab.empty() && ba.empty()) return std::nullopt;
    if (!ab.empty())
      if (auto e = b.receive(ab)) return e;
    if (!ba.empty())
      if (auto e = a.receive(ba)) return e;
  }
  FAIL("the ends kept talking");
  return std::nullopt;
}

}  // namespace

TEST_CASE("two ends with the same secret shake hands and exchange bytes both ways", "[secure]") {
  SecureChannel client(SecureChannel::Role::kClient, "token", "client");
  SecureChannel server(SecureChannel::Role::kServer, "token", "client");
  // Sent before the handshake completes: queued, delivered after it.
  REQUIRE_FALSE(client.send(bytesOf("hello")));
  REQUIRE_FALSE(shuttle(client, server));
  CHECK(client.established());
  CHECK(server.established());
  CHECK(server.takeIncoming() == bytesOf("hello"));

  // A frame larger than a TLS record (16 KiB), in both directions.
  Bytes big(1 << 20);
  std::iota(big.begin(), big.end(), std::uint8_t{0});
  REQUIRE_FALSE(server.send(big));
  REQUIRE_FALSE(client.send(bytesOf("more")));
  REQUIRE_FALSE(shuttle(client, server));
  CHECK(client.takeIncoming() == big);
  CHECK(server.takeIncoming() == bytesOf("more"));
  // Nothing in the clear on the wire.
  REQUIRE_FALSE(client.send(bytesOf("a plaintext marker")));
  const Bytes wire = client.takeOutgoing();
  CHECK(std::search(wire.begin(), wire.end(), std::begin("marker"), std::end("marker") - 1) == wire.end());
}

TEST_CASE("a different secret or purpose fails the handshake on both ends", "[secure]") {
  for (const auto& [secret, purpose] : {std::pair{"other", "client"}, std::pair{"token", "connect-back"}}) {
    SecureChannel client(SecureChannel::Role::kClient, secret, purpose);
    SecureChannel server(SecureChannel::Role::kServer, "token", "client");
    const auto e = shuttle(client, server);
    REQUIRE(e);
    CHECK(e->code == ErrorCode::kAuthFailed);
    CHECK_THAT(e->text, Contains("the handshake failed") && Contains("does not hold the same secret"));
    CHECK_FALSE(server.established());
    CHECK((server.failed() || client.failed()));
    // A failed channel stays failed.
    CHECK(server.failed() == bool(server.receive(Bytes{1, 2, 3})));
  }
}

TEST_CASE("an altered or replayed record is refused", "[secure]") {
  SecureChannel client(SecureChannel::Role::kClient, "token", "client");
  SecureChannel server(SecureChannel::Role::kServer, "token", "client");
  REQUIRE_FALSE(shuttle(client, server));

  REQUIRE_FALSE(client.send(bytesOf("set -dataset ct.json")));
  const Bytes record = client.takeOutgoing();
  REQUIRE_FALSE(server.receive(record));
  CHECK(server.takeIncoming() == bytesOf("set -dataset ct.json"));

  SECTION("replayed") {
    const auto e = server.receive(record);
    REQUIRE(e);
    CHECK(e->code == ErrorCode::kAuthFailed);
    CHECK(server.takeIncoming().empty());
  }
  SECTION("altered") {
    REQUIRE_FALSE(client.send(bytesOf("set -dataset ct.json")));
    Bytes altered = client.takeOutgoing();
    altered[altered.size() / 2] ^= 0x01;
    const auto e = server.receive(altered);
    REQUIRE(e);
    CHECK(e->code == ErrorCode::kAuthFailed);
    CHECK(server.takeIncoming().empty());
  }
  SECTION("not TLS at all") {
    SecureChannel fresh(SecureChannel::Role::kServer, "token", "client");
    const auto e = fresh.receive(bytesOf("PVR1 this is a plain frame, not a TLS record......"));
    REQUIRE(e);
    CHECK(e->code == ErrorCode::kAuthFailed);
  }
}

TEST_CASE("a relay without the secret can neither finish the handshake nor read or inject", "[secure]") {
  // The attack of the challenge-response scheme: a fake server between a
  // real client and pvrd. Without the secret it can only talk TLS with a
  // key of its own, and then the client refuses it.
  SecureChannel client(SecureChannel::Role::kClient, "token", "client");
  SecureChannel fakeServer(SecureChannel::Role::kServer, "guess", "client");
  const auto e = shuttle(client, fakeServer);
  REQUIRE(e);
  CHECK_FALSE(client.established());

  // Forwarding bytes unchanged only connects the client to pvrd: records
  // injected by the relay (encrypted under any key it has) are refused.
  SecureChannel client2(SecureChannel::Role::kClient, "token", "client");
  SecureChannel pvrd(SecureChannel::Role::kServer, "token", "client");
  REQUIRE_FALSE(shuttle(client2, pvrd));
  SecureChannel attackerClient(SecureChannel::Role::kClient, "guess", "client");
  SecureChannel attackerServer(SecureChannel::Role::kServer, "guess", "client");
  REQUIRE_FALSE(shuttle(attackerClient, attackerServer));
  REQUIRE_FALSE(attackerClient.send(bytesOf("render rotate 1000")));
  const auto injected = pvrd.receive(attackerClient.takeOutgoing());
  REQUIRE(injected);
  CHECK(injected->code == ErrorCode::kAuthFailed);
}
