#include "reply_book.h"

#include <utility>

namespace pvr::tcl {

TclError remoteError(const proto::ErrorMessage& e) {
  const std::string code(proto::errorCodeName(e.code));
  return TclError({"PVR", "REMOTE", code}, "server error " + code + ": " + e.text);
}

Sequence& ReplyBook::start(std::uint32_t id, std::string label, std::uint32_t total, Clock::time_point sent) {
  Sequence& seq = sequences[id];
  seq.id = id;
  seq.label = std::move(label);
  seq.total = total;
  seq.sent = sent;
  latestId_ = id;
  return seq;
}

Arrival ReplyBook::route(const proto::Decoded& d, Clock::time_point now) {
  const std::uint32_t id = d.info.requestId;
  Arrival a;
  a.id = id;
  const auto* error = std::get_if<proto::ErrorMessage>(&d.message);

  // Request id 0: news about the connection itself, Error or Close. An
  // Error fails whatever waits (open's handshake).
  if (id == 0) {
    if (error) {
      a.kind = Arrival::Kind::kConnectionError;
      a.error = remoteError(*error);
      for (auto& [pid, p] : pending)
        if (p.synchronous && !p.done) {
          p.error = a.error;
          p.done = true;
        }
    } else if (const auto* c = std::get_if<proto::Close>(&d.message)) {
      a.kind = Arrival::Kind::kClosed;
      a.reason = c->reason;
    }
    return a;
  }

  // A cancelled request: its answers are dropped up to the last one.
  if (dropped.count(id)) {
    if (d.info.final() || error) dropped.erase(id);
    return a;
  }

  // A render sequence: frames are recorded in place (never copied).
  if (auto s = sequences.find(id); s != sequences.end()) {
    Sequence& seq = s->second;
    if (const auto* f = std::get_if<proto::ImageFrame>(&d.message)) {
      FrameRecord r;
      r.frame = f->frameNumber;
      r.timing = f->timing;
      r.arrival = seconds(now - seq.sent);
      r.width = int(f->width);
      r.height = int(f->height);
      r.coarse = seq.reduction > 1 && f->frameNumber == 0;
      if (r.coarse) r.reduction = seq.reduction;
      seq.frames.push_back(r);
      a.kind = Arrival::Kind::kFrame;
      a.frame = f;
      a.complete = d.info.final() || seq.frames.size() >= seq.total;
      return a;
    }
    a.kind = Arrival::Kind::kSequenceEnded;
    if (error && error->code != proto::ErrorCode::kCancelled) a.error = remoteError(*error);
    if (!error)
      a.error = TclError({"PVR", "PROTOCOL", "UNEXPECTED_MESSAGE"},
                         "a render request was answered with a message that is no image");
    return a;
  }

  // A query or command: its replies up to FINAL.
  const auto p = pending.find(id);
  if (p == pending.end()) return a;
  Pending& pend = p->second;
  a.kind = Arrival::Kind::kAnswered;
  if (error) {
    pend.error = remoteError(*error);
    pend.done = true;
  } else {
    if (pend.replies.size() >= kMaxRepliesPerRequest) {
      // A server that never ends a request would grow this without bound
      // (3.1 GiB in 7 s): the session ends instead.
      a.kind = Arrival::Kind::kTooManyReplies;
      a.error = TclError({"PVR", "PROTOCOL", "LIMIT_EXCEEDED"},
                         peer_ + " sent more than " + std::to_string(kMaxRepliesPerRequest) +
                             " replies to one request without ending it; the session is closed");
      return a;
    }
    pend.replies.push_back(d.message);
    pend.done = d.info.final();
  }
  if (pend.done && !pend.synchronous) {
    a.kind = Arrival::Kind::kRequestDone;
    a.error = pend.error;
    pending.erase(p);
  }
  return a;
}

Arrival ReplyBook::refuse(std::uint32_t requestId, bool final, const TclError& error) {
  Arrival a;
  a.id = requestId;
  a.error = error;
  if (requestId != 0 && dropped.count(requestId)) {
    if (final) dropped.erase(requestId);
    a.kind = Arrival::Kind::kIgnored;
    a.error.reset();
    return a;
  }
  if (requestId != 0 && sequences.count(requestId)) {
    a.kind = Arrival::Kind::kSequenceEnded;
    a.complete = final;
    return a;
  }
  if (const auto p = pending.find(requestId); requestId != 0 && p != pending.end()) {
    // The reply it refused may have been the FINAL one or not: either way
    // the request cannot be answered whole any more.
    p->second.error = error;
    p->second.done = true;
    a.kind = Arrival::Kind::kAnswered;
    if (!p->second.synchronous) {
      a.kind = Arrival::Kind::kRequestDone;
      pending.erase(p);
    }
    return a;
  }
  a.kind = Arrival::Kind::kConnectionError;
  return a;
}

std::optional<Sequence> ReplyBook::finish(std::uint32_t id) {
  const auto it = sequences.find(id);
  if (it == sequences.end()) return std::nullopt;
  std::optional<Sequence> seq(std::move(it->second));
  sequences.erase(it);
  return seq;
}

void ReplyBook::remember(Sequence&& seq) {
  if (seq.id >= finished_.id) finished_ = std::move(seq);
}

const Sequence& ReplyBook::latest() const {
  const auto it = sequences.find(latestId_);
  return it != sequences.end() ? it->second : finished_;
}

void ReplyBook::failPending(const TclError& error) {
  for (auto& [id, p] : pending)
    if (!p.done) {
      p.error = error;
      p.done = true;
    }
  for (auto it = pending.begin(); it != pending.end();) it = it->second.synchronous ? std::next(it) : pending.erase(it);
}

void ReplyBook::clear() {
  pending.clear();
  if (auto it = sequences.find(latestId_); it != sequences.end()) remember(std::move(it->second));
  sequences.clear();
  dropped.clear();
}

bool ReplyBook::busy() const {
  if (!sequences.empty()) return true;
  for (const auto& [id, p] : pending)
    if (!p.synchronous && !p.done) return true;
  return false;
}

}  // namespace pvr::tcl
