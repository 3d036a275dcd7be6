#include "pvrd_link_thread.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>

#include "error.h"

namespace pvr::node {

namespace {

using Clock = std::chrono::steady_clock;

// Ciphertext the link may hold unwritten before the thread stops moving
// frames into it from the outbox: enough to keep the socket busy.
constexpr std::size_t kLinkBytes = std::size_t(4) << 20;

// How long a closing link may take to hand the client what is queued.
constexpr auto kCloseGrace = std::chrono::seconds(5);

// A request that asks the master for work, which an interactive render's
// full-quality frame gives way to (giveWayToNewer); queries do not.
bool asksForWork(const proto::Message& m) {
  return !proto::isQuery(m);
}

std::vector<std::uint8_t> encodeFinal(const proto::Message& m, std::uint32_t id, bool final = true) {
  return proto::encode(m, id, final ? proto::kFlagFinal : 0);
}

}  // namespace

LinkThread::LinkThread(std::unique_ptr<PvrdLink> link, std::function<void(std::uint32_t)> onCancel,
                       comm::Liveness* liveness)
    : link_(std::move(link)), onCancel_(std::move(onCancel)), liveness_(liveness) {
  wakeFd_ = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (wakeFd_ < 0) throw Error(ErrorCode::kIo, std::string("eventfd for the link thread: ") + std::strerror(errno));
  link_->stopBlocking();
  thread_ = std::thread([this] { run(); });
}

LinkThread::~LinkThread() {
  close();
  if (thread_.joinable()) thread_.join();
  ::close(wakeFd_);
}

void LinkThread::wake() {
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t n = ::write(wakeFd_, &one, sizeof one);
}

void LinkThread::pushOut(std::vector<std::uint8_t> bytes) {
  outboxBytes_ += bytes.size();
  outbox_.push_back(std::move(bytes));
}

std::optional<proto::Decoded> LinkThread::take() {
  std::unique_lock lock(mutex_);
  current_ = 0;  // the last one is answered
  currentIsRender_ = false;
  const comm::LivenessScope waiting(liveness_, comm::LivenessScope::Kind::kWaiting);
  changed_.wait(lock, [&] { return closed_ || closing_ || !requests_.empty(); });
  if (closed_ || closing_ || requests_.empty()) return std::nullopt;
  proto::Decoded frame = std::move(requests_.front());
  requests_.pop_front();
  current_ = frame.info.requestId;
  currentIsRender_ = proto::isRenderRequest(frame.message);
  return frame;
}

std::optional<proto::Decoded> LinkThread::takeIf(const std::function<bool(const proto::Message&)>& wanted) {
  const std::lock_guard lock(mutex_);
  const auto it = std::find_if(requests_.begin(), requests_.end(), [&](const proto::Decoded& d) { return wanted(d.message); });
  if (it == requests_.end()) return std::nullopt;
  proto::Decoded frame = std::move(*it);
  requests_.erase(it);
  return frame;
}

void LinkThread::send(const proto::Message& m, std::uint32_t id, bool final) {
  std::vector<std::uint8_t> bytes = encodeFinal(m, id, final);
  std::unique_lock lock(mutex_);
  const auto fits = [&] { return closed_ || outboxBytes_ == 0 || outboxBytes_ + bytes.size() <= kMaxOutboxBytes; };
  if (!fits()) {
    // The client takes frames slower than they render: wait for it.
    const comm::LivenessScope waiting(liveness_, comm::LivenessScope::Kind::kWaiting);
    changed_.wait(lock, fits);
  }
  if (closed_ || closing_) return;
  // The current request's last answer: it is answered, as take() would
  // say. The client may send its next request as soon as it reads this,
  // before the main thread is back in take(); a Status then must not wait
  // behind a request already answered.
  if (final && id != 0 && id == current_) {
    current_ = 0;
    currentIsRender_ = false;
  }
  // Nothing waits before it and the link is free: written now, without
  // waiting for the thread to be scheduled (on a loaded machine that took
  // 7 ms of an interactive render's first pixels). The thread is still
  // woken when the socket did not take it all.
  if (outbox_.empty()) {
    std::unique_lock linkLock(linkMutex_, std::try_to_lock);
    if (linkLock && link_->open() && link_->unwritten() < kLinkBytes) {
      link_->sendRaw(bytes);
      const bool unwritten = link_->unwritten() > 0;
      linkLock.unlock();
      lock.unlock();
      if (unwritten) wake();
      return;
    }
  }
  pushOut(std::move(bytes));
  lock.unlock();
  wake();
}

void LinkThread::setRendering(std::uint32_t id) {
  const std::lock_guard lock(mutex_);
  rendering_ = id;
  givesWay_ = 0;
}

bool LinkThread::giveWayToNewer(std::uint32_t id) {
  const std::lock_guard lock(mutex_);
  if (std::any_of(requests_.begin(), requests_.end(), [](const proto::Decoded& d) { return asksForWork(d.message); }))
    return true;
  givesWay_ = id;
  return false;
}

void LinkThread::publishStatus(proto::StatusReply status) {
  const std::lock_guard lock(mutex_);
  status_ = std::move(status);
}

void LinkThread::close(std::optional<proto::ErrorMessage> last) {
  {
    const std::lock_guard lock(mutex_);
    if (closing_ || closed_) return;
    if (last) pushOut(encodeFinal(*last, current_));
    closing_ = true;
    changed_.notify_all();
  }
  wake();
}

bool LinkThread::waitClosed(double seconds) {
  std::unique_lock lock(mutex_);
  return changed_.wait_for(lock, std::chrono::duration<double>(seconds), [&] { return closed_.load(); });
}

bool LinkThread::renderAhead() const {
  return rendering_ != 0 || currentIsRender_ ||
         std::any_of(requests_.begin(), requests_.end(), [](const proto::Decoded& d) { return proto::isRenderRequest(d.message); });
}

bool LinkThread::answersStatusAtOnce() const {
  // Only renders ahead of it: they change nothing a Status shows but the
  // frames, so it need not wait for them. Behind anything else it waits
  // its turn, to show what that request changed.
  if (current_ != 0 && !currentIsRender_) return false;
  if (current_ == 0 && requests_.empty()) return false;  // the main thread answers at once
  return std::all_of(requests_.begin(), requests_.end(), [](const proto::Decoded& d) { return proto::isRenderRequest(d.message); });
}

void LinkThread::dispatch(proto::Decoded frame) {
  const std::uint32_t id = frame.info.requestId;
  std::unique_lock lock(mutex_);
  // Stops the request the main thread runs: its render ends at the next
  // tile on every rank (onCancel) or before its next wave (cancelled()).
  const auto stopCurrent = [&] {
    const std::uint32_t target = current_;
    if (target == 0 || cancelled_.exchange(target) == target) return;
    lock.unlock();
    onCancel_(target);
    lock.lock();
  };
  if (std::holds_alternative<proto::StatusRequest>(frame.message) && answersStatusAtOnce()) {
    pushOut(encodeFinal(status_, id));
    return;
  }
  if (const auto* cancel = std::get_if<proto::Cancel>(&frame.message)) {
    if (cancel->target != 0 && cancel->target == current_) {
      stopCurrent();
    } else {
      const auto queued = std::find_if(requests_.begin(), requests_.end(),
                                       [&](const proto::Decoded& d) { return d.info.requestId == cancel->target; });
      if (queued != requests_.end()) {
        requests_.erase(queued);
        pushOut(encodeFinal(proto::ErrorMessage{proto::ErrorCode::kCancelled, "cancelled before it started"}, cancel->target));
      }
    }
    // Ok also when the target already finished (docs/protocol.md).
    pushOut(encodeFinal(proto::Ok{}, id));
    return;
  }
  if (std::holds_alternative<proto::Close>(frame.message)) {
    // The client leaves: nothing queued is wanted any more, and a render
    // in progress need not finish.
    if (rendering_ != 0) stopCurrent();
    requests_.clear();
    requests_.push_back(std::move(frame));
    changed_.notify_all();
    return;
  }
  if (requests_.size() >= kMaxQueuedRequests) {
    pushOut(encodeFinal(proto::ErrorMessage{proto::ErrorCode::kLimitExceeded,
                                            "more than " + std::to_string(kMaxQueuedRequests) + " requests wait for the " +
                                                (renderAhead() ? "sequence" : "request") + " in progress; this one is dropped"},
                        id));
    return;
  }
  const bool newer = asksForWork(frame.message);
  requests_.push_back(std::move(frame));
  changed_.notify_all();
  if (newer && givesWay_ != 0 && givesWay_ == current_) stopCurrent();
}

void LinkThread::run() {
  auto nextHeartbeat = Clock::now();
  std::optional<Clock::time_point> closeBy;
  for (;;) {
    // Frames from the outbox into the link, while it holds little unwritten.
    {
      const std::lock_guard lock(mutex_);
      const std::lock_guard linkLock(linkMutex_);
      bool moved = false;
      while (!outbox_.empty() && link_->open() && link_->unwritten() < kLinkBytes) {
        link_->sendRaw(outbox_.front());
        outboxBytes_ -= outbox_.front().size();
        outbox_.pop_front();
        moved = true;
      }
      if (moved) changed_.notify_all();
      if (closing_ && !closeBy) closeBy = Clock::now() + kCloseGrace;
      if (closing_ && outbox_.empty() && link_->unwritten() == 0) break;
    }
    std::unique_lock linkLock(linkMutex_);
    if (!link_->open() || (closeBy && Clock::now() > *closeBy)) break;
    const auto now = Clock::now();
    if (now >= nextHeartbeat) {
      link_->send(proto::Heartbeat{}, 0);
      nextHeartbeat = now + std::chrono::seconds(proto::kHeartbeatSeconds);
    }
    pollfd fds[2] = {{link_->fd(), short(POLLIN | (link_->unwritten() ? POLLOUT : 0)), 0}, {wakeFd_, POLLIN, 0}};
    linkLock.unlock();
    const auto wait = std::chrono::duration_cast<std::chrono::milliseconds>(nextHeartbeat - now).count() + 1;
    if (::poll(fds, 2, int(std::min<long long>(wait, 1000))) < 0 && errno != EINTR) break;
    if (fds[1].revents & POLLIN) {
      std::uint64_t count = 0;
      [[maybe_unused]] const ssize_t n = ::read(wakeFd_, &count, sizeof count);
    }
    if (fds[0].revents & POLLOUT) {
      const std::lock_guard lock(linkMutex_);
      link_->writeSome();
    }
    if (fds[0].revents & (POLLIN | POLLHUP | POLLERR)) {
      // The link is held for each read, not while a request is dispatched
      // (dispatch takes mutex_, which send holds while it tries the link).
      for (;;) {
        std::unique_lock lock(linkMutex_);
        auto frame = link_->next(false);
        lock.unlock();
        if (!frame) break;
        dispatch(std::move(*frame));
      }
    }
  }
  const std::lock_guard linkLock(linkMutex_);
  link_->close();
  const std::lock_guard lock(mutex_);
  closed_ = true;
  changed_.notify_all();
}

}  // namespace pvr::node
