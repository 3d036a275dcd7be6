// Dispatcher: the per-side action table. pvrd fills one with handlers for the
// messages a client sends, pvrsh one for the messages a server sends; a
// message without a handler goes to the fallback, which normally answers
// Error kUnexpectedMessage.
//
//   Dispatcher server;
//   server.on<Hello>([&](const Hello& hello, const FrameInfo& info) { ... });
//   server.otherwise([&](const Message& m, const FrameInfo& info) { ... });
//   while (auto frame = decoder.pop()) server.dispatch(*frame);
#pragma once

#include <array>
#include <functional>
#include <utility>
#include <variant>

#include "frame_codec.h"
#include "message_table.h"
#include "protocol_messages.h"

namespace pvr::proto {

class Dispatcher {
 public:
  using Fallback = std::function<void(const Message& message, const FrameInfo& info)>;

  // Handles messages of type T; replaces an earlier handler for T.
  // `handler` is callable as handler(const T&, const FrameInfo&).
  template <class T, class F>
  void on(F handler) {
    handlers_[messageIndex<T>()] = [handler = std::move(handler)](const Message& message, const FrameInfo& info) {
      handler(std::get<T>(message), info);
    };
  }

  // Called for a message type with no handler.
  void otherwise(Fallback fallback) { fallback_ = std::move(fallback); }

  bool handles(const Message& message) const { return static_cast<bool>(handlers_[message.index()]); }

  // Runs the handler for the message; true if there was one (false after
  // the fallback, or when there is neither).
  bool dispatch(const Message& message, const FrameInfo& info) const;
  bool dispatch(const Decoded& frame) const { return dispatch(frame.message, frame.info); }

 private:
  std::array<Fallback, std::variant_size_v<Message>> handlers_;
  Fallback fallback_;
};

}  // namespace pvr::proto
