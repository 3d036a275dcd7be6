// The master rank's connection back to its pvrd session handler: the one
// place of the node that touches a socket. Frames in are decoded
// incrementally; frames out are encoded protocol messages.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "pvr_protocol.h"

namespace pvr::node {

class PvrdLink {
 public:
  // Connects to HOST:PORT (numeric IPv4); throws pvr::Error (kIo) naming
  // the address and the reason.
  PvrdLink(const std::string& host, int port);
  ~PvrdLink();
  PvrdLink(const PvrdLink&) = delete;
  PvrdLink& operator=(const PvrdLink&) = delete;

  bool open() const { return open_; }
  // Sends one message; a failed write closes the link.
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
  int fd_ = -1;
  bool open_ = false;
  proto::FrameDecoder decoder_;
};

}  // namespace pvr::node
