// Connection: one non-blocking TCP connection to pvrd on the Tcl event loop.
//
// Connecting, reading and writing all happen in Tcl file handlers
// (Tcl_CreateFileHandler), so any number of connections and a Tk GUI stay
// live at once. Bytes in go through a FrameDecoder; each decoded message is
// handed to the Listener. Bytes out are queued and written as the socket
// accepts them. The connection never blocks the interpreter. Once
// startSecure() is called every byte in and out goes through a
// SecureChannel keyed by the token (docs/protocol.md, "The secure channel").
#pragma once

#include <tcl.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pvr_protocol.h"
#include "secure_channel.h"
#include "tcl_util.h"

namespace pvr::tcl {

class Connection {
 public:
  // What the owner hears. A listener may destroy the Connection from inside
  // either call; the connection notices and touches nothing after.
  class Listener {
   public:
    virtual ~Listener() = default;
    virtual void onMessage(const proto::Decoded& message) = 0; // one decoded frame
    virtual void onFailure(const TclError& error) = 0;         // once; the socket is closed after it
  };

  // Resolves `host` and starts a non-blocking connect. From the event loop
  // the connect then finishes (connected() turns true, and frames queued by
  // send meanwhile go out) or fails: onFailure, with {PVR CONNECT TIMEOUT}
  // after `timeoutSeconds`. Throws TclError {PVR CONNECT RESOLVE},
  // {PVR CONNECT REFUSED} or {PVR CONNECT SOCKET} for failures known at once.
  Connection(Listener& listener, const std::string& host, int port, double timeoutSeconds);
  ~Connection();
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;

  // Queues one frame and writes what the socket takes now. Returns false
  // once the connection has failed or closed (the frame is dropped).
  bool send(const proto::Message& message, std::uint32_t requestId);

  // Starts the secure channel keyed by `token`: the server asked for it in
  // Welcome. Frames sent from now on wait in the channel until its
  // handshake completes; a handshake the server fails (another token, or a
  // server that is not pvrd) fails the connection with {PVR AUTH FAILED}.
  void startSecure(const std::string& token);

  bool connected() const { return state_ == State::kConnected; }
  bool failed() const { return state_ == State::kFailed; }

 private:
  enum class State { kConnecting, kConnected, kFailed };

  static void fileProc(ClientData data, int mask);
  static void timeoutProc(ClientData data);
  void finishConnect();
  void readSome();
  void writeSome();
  void updateMask();
  void fail(std::vector<std::string> code, const std::string& message);
  void closeSocket();
  // Appends bytes for the socket to the queue.
  void queue(std::span<const std::uint8_t> bytes);

  Listener& listener_;
  std::string peer_;  // "host:port" for messages
  int fd_ = -1;
  State state_ = State::kConnecting;
  int mask_ = 0;                          // file handler mask in force
  Tcl_TimerToken timer_ = nullptr;        // connect timeout
  std::vector<std::uint8_t> out_;         // bytes queued for the socket
  std::size_t outDone_ = 0;               // bytes of out_ already written
  std::unique_ptr<proto::SecureChannel> channel_;  // after startSecure()
  proto::FrameDecoder decoder_;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);  // false once destroyed
};

}  // namespace pvr::tcl
