// The master rank's connection back to its pvrd session handler: the one
// place of the node that touches a socket. Every byte travels inside a
// SecureChannel keyed by the job secret (docs/protocol.md, "The secure
// channel"), so only the pvrd that launched the job can talk to it and no
// one in between can read or alter the frames. Frames in are decoded
// incrementally; frames out are encoded protocol messages.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "pvr_protocol.h"
#include "secure_channel.h"

namespace pvr::node {

class PvrdLink {
 public:
  // Connects to HOST:PORT (numeric IPv4) and completes the secure
  // channel's handshake with the job secret, waiting at most
  // kHandshakeSeconds; throws pvr::Error (kIo, or kInvalidArgument for an
  // empty secret) naming the address and the reason.
  PvrdLink(const std::string& host, int port, const std::string& jobSecret);
  static constexpr int kHandshakeSeconds = 30;
  ~PvrdLink();
  PvrdLink(const PvrdLink&) = delete;
  PvrdLink& operator=(const PvrdLink&) = delete;

  bool open() const { return open_; }
  int fd() const { return fd_; }
  // From now on writes never block: what the socket does not take stays
  // in the link (unwritten()) until writeSome() is called when the socket
  // can take more. The link thread (pvrd_link_thread.h) switches to this
  // once the handshake and JobHello are through.
  void stopBlocking();
  std::size_t unwritten() const { return out_.size() - outDone_; }
  void writeSome();
  // Sends one message (queues it, without blocking, after stopBlocking());
  // a failed write closes the link.
  void send(const proto::Message& m, std::uint32_t id, bool final = true);
  // Sends bytes already framed (a refusal before the session starts).
  void sendRaw(std::span<const std::uint8_t> bytes);
  // The next decoded frame: from what was read already, then the socket,
  // waiting for it when `wait`, else only what is there now. nullopt when
  // nothing is there, or the link closed (a malformed frame is answered
  // with its protocol error, then the link closes).
  std::optional<proto::Decoded> next(bool wait);
  void close();

 private:
  // Moves what the channel has for the socket to out_ and writes it: all
  // of it while blocking, else what the socket takes now. A failed write
  // closes the link.
  void flush();
  // Reads what the socket has (waiting up to timeoutMs, -1 for ever) into
  // the channel. False when the link closed or the channel failed.
  bool readSome(int timeoutMs);

  int fd_ = -1;
  bool open_ = false;
  bool blocking_ = true;
  std::unique_ptr<proto::SecureChannel> channel_;
  proto::FrameDecoder decoder_;
  std::vector<std::uint8_t> out_;  // ciphertext for the socket; the first outDone_ bytes are written
  std::size_t outDone_ = 0;
};

}  // namespace pvr::node
