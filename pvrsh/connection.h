// Connection: one non-blocking TCP connection to pvrd on the Tcl event loop.
//
// Connecting, reading and writing all happen in Tcl file handlers
// (Tcl_CreateFileHandler), so any number of connections and a Tk GUI stay
// live at once. Bytes in go through a FrameIntake (frame_intake.h); each
// decoded message is handed to the Listener, and so is each frame refused
// whole for its size (the stream goes on after it). A frame that begins and
// does not end within the frame timeout fails the connection. Bytes out are queued and written as the socket
// accepts them. The connection never blocks the interpreter. Once
// startSecure() is called every byte in and out goes through a
// SecureChannel keyed by the token (docs/protocol.md, "The secure channel").
#pragma once

#include <tcl.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "frame_intake.h"
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
    virtual void onRefused(const FrameIntake::Refused& frame) = 0; // one frame too large, skipped
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

  // How long the rest of a frame may take once its first byte is in
  // (the session's -timeout); then the connection fails with
  // {PVR PROTOCOL TIMEOUT}. The clock starts afresh with each frame, so a
  // stream of frames that each arrive in time never trips it.
  void setFrameTimeout(double seconds) { frameTimeout_ = seconds; }

  bool connected() const { return state_ == State::kConnected; }
  bool failed() const { return state_ == State::kFailed; }

 private:
  enum class State { kConnecting, kConnected, kFailed };

  static void fileProc(ClientData data, int mask);
  static void timeoutProc(ClientData data);
  static void frameTimeoutProc(ClientData data);
  // Starts the half-frame timer when a frame has begun, stops it when none has.
  void watchFrame();
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
  Tcl_TimerToken frameTimer_ = nullptr;   // half-frame timeout, while a frame is begun
  double frameTimeout_ = 30;              // seconds; setFrameTimeout
  std::uint64_t framesEndedSeen_ = 0;     // intake_.framesEnded() when the timer was last looked at
  std::vector<std::uint8_t> out_;         // bytes queued for the socket
  std::size_t outDone_ = 0;               // bytes of out_ already written
  std::unique_ptr<proto::SecureChannel> channel_;  // after startSecure()
  FrameIntake intake_;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);  // false once destroyed
};

}  // namespace pvr::tcl
