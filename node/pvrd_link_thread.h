// The master's link to pvrd, served by a thread of its own so that the
// master answers while a frame renders (docs/runtime.md, "Liveness").
//
// The secure channel (an OpenSSL object) is not thread-safe: every read
// and write on the link holds linkMutex_. This thread does them all but
// one: send() writes a message itself when nothing waits in the outbox and
// the link is free at that moment, so a frame does not wait for this
// thread to be scheduled. It decodes the client's
// requests and
//   - answers a StatusRequest at once when only renders are ahead of it
//     (running or queued), from the snapshot the main thread publishes
//     after every request and wave (the session, and the frames sent so
//     far); behind any other request it waits its turn, so that it shows
//     what that request changed;
//   - answers a Cancel at once: of the running render, it raises the stop
//     the ray casters check between tiles (onCancel, rank_watch.h); of a
//     request still queued, it takes it off the queue and answers it with
//     Error CANCELLED;
//   - stops the render in progress when it gives way to newer requests
//     (giveWayToNewer) and one arrives, as a Cancel would;
//   - queues every other request for the main thread, in order, at most
//     kMaxQueuedRequests of them (LIMIT_EXCEEDED beyond: a flood grew rank
//     0 by 1.76 GiB in 18 s before);
//   - sends a Heartbeat every proto::kHeartbeatSeconds, so the handler sees
//     rank 0 itself stop.
// The main thread's frames reach it through an outbox bounded in bytes (a
// client that does not read holds up the renders, not rank 0's memory),
// woken by an eventfd. Writes never block the thread: it keeps reading
// while the client is slow to take a frame.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "liveness.h"
#include "pvrd_link.h"

namespace pvr::node {

class LinkThread {
 public:
  // Requests queued for the main thread; more are refused.
  static constexpr std::size_t kMaxQueuedRequests = 64;
  // Frame bytes the main thread may have waiting in the outbox before
  // send() waits for the client to take some.
  static constexpr std::size_t kMaxOutboxBytes = std::size_t(64) << 20;

  // Takes over `link` (handshake and JobHello done). `onCancel(id)` runs
  // on this thread when a Cancel stops the running render `id`.
  // `liveness`: the main thread counts as waiting while it waits here.
  LinkThread(std::unique_ptr<PvrdLink> link, std::function<void(std::uint32_t)> onCancel, comm::Liveness* liveness);
  ~LinkThread();  // flushes what is queued (a few seconds at most), closes, joins
  LinkThread(const LinkThread&) = delete;
  LinkThread& operator=(const LinkThread&) = delete;

  // Main thread. The next request, waiting for one; nullopt once the link
  // closed. The request taken is the current one until the next take().
  std::optional<proto::Decoded> take();
  // The first queued request `wanted` accepts, without waiting.
  std::optional<proto::Decoded> takeIf(const std::function<bool(const proto::Message&)>& wanted);
  // Sends one message; waits while the outbox is full. Any thread.
  void send(const proto::Message& m, std::uint32_t id, bool final = true);
  // The render of request `id` starts or ends (0): while one runs, Status
  // is answered from `status` at once and Cancel stops it.
  void setRendering(std::uint32_t id);
  void publishStatus(proto::StatusReply status);
  // Main thread, for the render `id` in progress (an interactive render
  // about to draw its full-quality frame): from now until it ends, a newer
  // request that asks for work (anything but Status, Performance and
  // Catalog requests) stops it as a Cancel would. True when such a
  // request is queued already; then nothing is stopped, the caller ends
  // the render itself.
  bool giveWayToNewer(std::uint32_t id);
  // True once a Cancel named the render `id` in progress.
  bool cancelled(std::uint32_t id) const { return id != 0 && cancelled_.load() == id; }
  // Sends what is queued, then closes the link (the client's Close, or a
  // fatal report: `last`, answering the current request).
  void close(std::optional<proto::ErrorMessage> last = std::nullopt);
  bool open() const { return !closed_.load(); }
  // Waits up to `seconds` for the thread to have written everything and
  // closed the link; true if it did.
  bool waitClosed(double seconds);

 private:
  void run();
  void wake();
  // On this thread, for each decoded request.
  void dispatch(proto::Decoded frame);
  // A render runs or waits (mutex_ held).
  bool renderAhead() const;
  // A Status now need not wait for the requests ahead of it (mutex_ held).
  bool answersStatusAtOnce() const;
  // Queues encoded plaintext for the thread (mutex_ held).
  void pushOut(std::vector<std::uint8_t> bytes);

  std::unique_ptr<PvrdLink> link_;
  std::function<void(std::uint32_t)> onCancel_;
  comm::Liveness* liveness_;
  int wakeFd_ = -1;

  // link_: held for each use of it; taken after mutex_ when both are held
  // (send only tries it, so no order can deadlock).
  std::mutex linkMutex_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;  // requests queued, outbox drained, link closed
  std::deque<proto::Decoded> requests_;
  std::deque<std::vector<std::uint8_t>> outbox_;
  std::size_t outboxBytes_ = 0;
  std::uint32_t current_ = 0;    // the request the main thread took last, until its last answer is sent; 0: none
  bool currentIsRender_ = false;
  std::uint32_t rendering_ = 0;  // the render in progress; 0: none
  std::uint32_t givesWay_ = 0;   // the render a newer request stops (giveWayToNewer); 0: none
  proto::StatusReply status_;
  bool closing_ = false;
  std::atomic<std::uint32_t> cancelled_{0};
  std::atomic<bool> closed_{false};
  std::thread thread_;
};

}  // namespace pvr::node
