// SecureChannel: TLS 1.3 with an external pre-shared key (RFC 8446,
// psk_dhe_ke) over any byte stream, without sockets.
//
// A token authenticates a client to pvrd and the job secret a master's
// connect-back to pvrd. A challenge-response over the plain stream proves
// the secret once but protects nothing after it, and a fake server can
// relay the challenge to a real client and use its answer. Inside TLS
// with a key derived from the secret, both ends prove the secret to each
// other in a handshake bound to this connection (its transcript and fresh
// Diffie-Hellman shares), and every later byte is encrypted and
// authenticated with a record sequence number, so relaying, tampering and
// replay fail. No certificates: the secret is the only credential.
//
// Sans-IO: the owner moves ciphertext between the socket and the channel
// (receive, takeOutgoing) and plaintext between the channel and its frame
// codec (send, takeIncoming), so the Tcl event loop, pvrd's poll loop and
// the master's blocking socket all use the same channel. docs/protocol.md,
// "Secure channel", says where in a conversation it starts.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "protocol_error.h"

namespace pvr::proto {

// The purposes the channel is keyed for (SecureChannel's `purpose`): a
// client's connection to pvrd, keyed by the token; the master's
// connect-back to its session handler, keyed by the job secret.
inline constexpr std::string_view kClientPurpose = "client";
inline constexpr std::string_view kConnectBackPurpose = "connect-back";

class SecureChannel {
 public:
  enum class Role { kClient, kServer };

  // `secret` is the shared secret (token or job secret). The TLS key is
  // HKDF-SHA256(secret) with `purpose` in its info, so one secret used for
  // two purposes yields two unrelated keys. A client has its ClientHello
  // ready in takeOutgoing() at once. Throws std::runtime_error only when
  // OpenSSL cannot set up at all (out of memory, no TLS 1.3).
  SecureChannel(Role role, std::string_view secret, std::string_view purpose);
  ~SecureChannel();
  SecureChannel(const SecureChannel&) = delete;
  SecureChannel& operator=(const SecureChannel&) = delete;

  // Bytes read from the socket. An error (kAuthFailed) when the peer does
  // not hold the secret, or the bytes were altered, replayed or are not
  // TLS; the channel is then failed and stays so.
  std::optional<ProtocolError> receive(std::span<const std::uint8_t> ciphertext);
  // Plaintext for the peer; queued until the handshake completes.
  std::optional<ProtocolError> send(std::span<const std::uint8_t> plaintext);

  // Ciphertext to write to the socket now (handshake flights or records).
  std::vector<std::uint8_t> takeOutgoing();
  // Plaintext that arrived.
  std::vector<std::uint8_t> takeIncoming();

  bool established() const { return established_; }
  bool failed() const { return failure_.has_value(); }

 private:
  struct Tls;  // OpenSSL objects (secure_channel.cpp)

  std::optional<ProtocolError> pump();
  std::optional<ProtocolError> fail(const char* during);

  std::unique_ptr<Tls> tls_;
  bool established_ = false;
  std::vector<std::uint8_t> pendingPlain_;   // queued by send before the handshake completed
  std::vector<std::uint8_t> incomingPlain_;  // decrypted, not yet taken
  std::optional<ProtocolError> failure_;
};

}  // namespace pvr::proto
