// ReplyBook: which request each server message answers, and what pvrsh
// keeps of the requests in flight (the pure part of session_arrivals.cpp).
//
// It knows no Tcl and no socket: Session asks it to route every decoded
// message and then does what the answer says (sinks, reports, Cancel,
// ending the session). The fuzzer fuzz/pvrsh_messages_fuzz.cpp drives it
// with arbitrary server messages the same way.
//
// Cost: routing a message is O(log n) in the requests in flight and O(1)
// amortised in the frames of a sequence. A sequence's frame records live
// in one place, its entry in `sequences` while in flight and the latest
// finished one after; nothing copies them per frame (issue 15, finding 15:
// a copy per frame made 40000 frames take 18.3 s).
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "pvr_protocol.h"
#include "tcl_error.h"

namespace pvr::tcl {

using Clock = std::chrono::steady_clock;

// Seconds in a duration, for timings.
inline double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// Non-final replies one request may have (a SessionOpen waiting in a batch
// queue gets one per change of state; nothing else gets more than a few).
inline constexpr std::size_t kMaxRepliesPerRequest = 1000;

// One frame's record: the server's timing breakdown and when it arrived.
struct FrameRecord {
  std::uint32_t frame = 0;
  proto::FrameTiming timing;
  double arrival = 0;  // seconds since the request was sent
  int width = 0, height = 0;  // the frame's own size (a coarse frame's is reduced)
  bool coarse = false;  // the coarse frame of an interactive render (proto::RenderInteractive)
  int reduction = 1;    // a coarse frame's pixels per axis: the client zooms it by this
};

// A render request in flight: RenderFrame, RenderRotation or RenderTimeSteps.
struct Sequence {
  std::uint32_t id = 0;      // request id
  std::string label;         // "rotate 0,1,0 15,59:60" for reports
  std::uint32_t total = 0;   // frames expected
  Clock::time_point sent;
  std::vector<FrameRecord> frames;
  bool cancelled = false;    // ended early (cancel, or a frame pvrsh could not deliver)
  // RenderInteractive's reduction: frame 0 is coarse, at 1/reduction of the
  // image size per axis, and frame 1 full; 0: not interactive.
  int reduction = 0;
};

// A request whose answer someone waits for (open, queries) or that only
// reports failure (SetScene, SetLayout, Cancel).
struct Pending {
  bool synchronous = false;             // a caller runs the event loop for it
  bool done = false;
  std::vector<proto::Message> replies;  // every answer up to FINAL
  std::optional<TclError> error;
};

// What one server message means; ReplyBook::route has already recorded it.
struct Arrival {
  enum class Kind {
    kIgnored,          // for a cancelled request, or a request pvrsh does not know
    kConnectionError,  // request id 0, Error: about the connection (`error`)
    kClosed,           // request id 0, Close: the server ends the session (`reason`)
    kFrame,            // an ImageFrame of sequence `id`, recorded; `complete` when it is the last
    kSequenceEnded,    // sequence `id` was answered by an Error (`error`, none when CANCELLED) or a non-image
    kAnswered,         // a reply of pending request `id` recorded (it may be done now)
    kRequestDone,      // asynchronous request `id` finished and was retired; `error` when it failed
    kTooManyReplies,   // request `id` passed kMaxRepliesPerRequest: the session must end (`error`)
  };
  Kind kind = Kind::kIgnored;
  std::uint32_t id = 0;
  bool complete = false;                     // kFrame, or kSequenceEnded by refuse(): that was its last frame
  const proto::ImageFrame* frame = nullptr;  // kFrame: inside the routed message
  std::optional<TclError> error;
  std::string reason;                        // kClosed
};

class ReplyBook {
 public:
  // `peer` names the server in error texts ("127.0.0.1:7350").
  explicit ReplyBook(std::string peer = {}) : peer_(std::move(peer)) {}
  void setPeer(std::string peer) { peer_ = std::move(peer); }

  // A request other than a render went out with id `id`.
  void expect(std::uint32_t id, bool synchronous) { pending[id].synchronous = synchronous; }
  // A render request went out with id `id`; it becomes the latest sequence.
  Sequence& start(std::uint32_t id, std::string label, std::uint32_t total, Clock::time_point sent);

  // Records what `message` answers and says what it means. `now` times frames.
  Arrival route(const proto::Decoded& message, Clock::time_point now);

  // A frame for request `requestId` that the receiver refused whole
  // (`error`: too large) while the stream goes on. The request it answers
  // fails with the error: a pending one as kAnswered or kRequestDone, a
  // sequence as kSequenceEnded; for request id 0 or an unknown request it
  // is kConnectionError (the session cannot tell what it missed). `final`:
  // the frame had FINAL set.
  Arrival refuse(std::uint32_t requestId, bool final, const TclError& error);

  // Takes sequence `id` out of flight (nullopt when it is not in flight).
  // Hand it to remember() once done with it.
  std::optional<Sequence> finish(std::uint32_t id);
  // Keeps `seq` as the latest finished sequence unless a newer one is kept.
  void remember(Sequence&& seq);
  // The latest sequence: the newest one started, in flight or finished
  // (an empty Sequence, id 0, before any).
  const Sequence& latest() const;

  // Answers still to come for request `id` are dropped (cancelled or
  // abandoned); it is forgotten when its FINAL answer or Error arrives.
  void drop(std::uint32_t id) { dropped.insert(id); }

  // Every request not yet done fails with `error`; asynchronous ones are
  // retired (a synchronous caller still finds its entry, with the error).
  void failPending(const TclError& error);
  // The connection is gone or new: everything in flight is forgotten (the
  // newest sequence in flight becomes the latest).
  void clear();

  // A sequence in flight, or an asynchronous request not yet answered.
  bool busy() const;

  std::map<std::uint32_t, Pending> pending;    // by request id
  std::map<std::uint32_t, Sequence> sequences; // in flight, by request id
  std::set<std::uint32_t> dropped;             // ids whose answers are ignored

 private:
  std::string peer_;
  std::uint32_t latestId_ = 0;  // the newest sequence started
  Sequence finished_;           // the newest sequence finished
};

// The server's Error as the Tcl error {PVR REMOTE <code>}.
TclError remoteError(const proto::ErrorMessage& e);

}  // namespace pvr::tcl
