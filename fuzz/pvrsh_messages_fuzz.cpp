// libFuzzer target for pvrsh's handling of what a server sends.
//
// The input is a script of client actions and server bytes, interleaved:
// each step is one byte choosing the action, then its arguments.
//   0: a query or command goes out (its id next; bit 3: synchronous)
//   1: a render goes out (1 to 8 frames expected)
//   2: `cancel`: every sequence in flight is dropped and ended
//   3: server bytes: a 16-bit count, then that many bytes for the
//      connection's FrameIntake, in one read
//   4: the synchronous callers take their finished answers
// Server bytes go through the code pvrsh runs (pvrsh/frame_intake.cpp,
// pvrsh/reply_book.cpp), and each routed message is acted on as
// Session::act does, without Tcl: frames are decoded by the protocol's
// pixel codec as decodePixels does, a frame that fails ends its sequence
// early (dropped), a Close, a flood of replies or a broken stream ends the
// session (everything in flight fails; a new connection starts).
//
// After every step the bookkeeping must hold: a sequence in flight has
// fewer frames than it expects (it ends at its last), no request keeps
// more than kMaxRepliesPerRequest replies, no dropped id is in flight,
// and the latest sequence is one that went out. Any breach aborts, which
// libFuzzer reports as a crash; the sanitizers report the rest.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <span>
#include <vector>

#include "frame_intake.h"
#include "pvr_protocol.h"
#include "reply_book.h"

namespace {

using namespace pvr;
using namespace pvr::tcl;

void require(bool condition, const char* what) {
  if (!condition) {
    std::fprintf(stderr, "pvrsh messages fuzz: %s\n", what);
    std::abort();
  }
}

// One connection and its requests, as a Session holds them.
struct Client {
  ReplyBook book{"fuzz:1"};
  std::unique_ptr<FrameIntake> intake = std::make_unique<FrameIntake>();
  std::uint32_t nextId = 1;
  const Clock::time_point now{};  // frames' arrival times do not matter here

  // Session::abandonSequence: drop what is still to come, end it.
  void abandon(std::uint32_t id, bool complete) {
    if (!complete) book.drop(id);
    if (auto seq = book.finish(id)) book.remember(std::move(*seq));
  }

  void finish(std::uint32_t id) {
    if (auto seq = book.finish(id)) book.remember(std::move(*seq));
  }

  // Session::endSession then a new open: all in flight fails, a fresh stream.
  void endSession(const TclError& error) {
    book.failPending(error);
    std::vector<std::uint32_t> ids;
    for (const auto& [id, seq] : book.sequences) ids.push_back(id);
    for (std::uint32_t id : ids) finish(id);
    book.clear();
    intake = std::make_unique<FrameIntake>();
  }

  // Session::act, without the Tcl side of it (sinks, reports).
  void act(const Arrival& a) {
    switch (a.kind) {
      case Arrival::Kind::kIgnored:
      case Arrival::Kind::kAnswered:
      case Arrival::Kind::kConnectionError:
      case Arrival::Kind::kRequestDone:
        return;
      case Arrival::Kind::kClosed:
      case Arrival::Kind::kTooManyReplies:
        endSession(a.error ? *a.error : TclError({"PVR", "CONNECT", "CLOSED"}, a.reason));
        return;
      case Arrival::Kind::kFrame: {
        require(a.frame != nullptr, "a frame arrival without its frame");
        const auto pixels = proto::decompressPixels(*a.frame);
        if (std::holds_alternative<proto::ProtocolError>(pixels)) {
          require(!std::get<proto::ProtocolError>(pixels).text.empty(), "a pixel error without text");
          abandon(a.id, a.complete);
        } else if (a.complete) {
          finish(a.id);
        }
        return;
      }
      case Arrival::Kind::kSequenceEnded:
        if (a.error && a.error->code().back() == "FRAME_TOO_LARGE")
          abandon(a.id, a.complete);
        else
          finish(a.id);
        return;
    }
  }

  void serverBytes(std::span<const std::uint8_t> bytes) {
    intake->feed(bytes);
    while (auto item = intake->pop()) {
      if (const auto* d = std::get_if<proto::Decoded>(&*item)) {
        act(book.route(*d, now));
      } else {
        const auto& r = std::get<FrameIntake::Refused>(*item);
        require(r.error.code == proto::ErrorCode::kFrameTooLarge, "a refusal that is not for size");
        const std::string code(proto::errorCodeName(r.error.code));
        const Arrival a = book.refuse(r.header.requestId, (r.header.flags & proto::kFlagFinal) != 0,
                                      TclError({"PVR", "PROTOCOL", code}, r.error.text));
        if (a.kind == Arrival::Kind::kConnectionError)
          endSession(*a.error);
        else
          act(a);
      }
    }
    if (intake->error()) endSession(TclError({"PVR", "PROTOCOL"}, intake->error()->text));
  }

  void check() const {
    for (const auto& [id, seq] : book.sequences) {
      require(seq.id == id, "a sequence filed under another id");
      require(seq.frames.size() < seq.total, "a sequence in flight past its last frame");
      require(!book.dropped.count(id), "a dropped id still in flight");
      require(id < nextId, "a sequence that never went out");
    }
    for (const auto& [id, p] : book.pending) {
      require(p.replies.size() <= kMaxRepliesPerRequest, "a request kept more replies than the limit");
      require(id < nextId, "a pending request that never went out");
    }
    require(book.latest().id < nextId, "the latest sequence never went out");
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::span<const std::uint8_t> in(data, size);
  Client client;
  const auto take = [&in](std::size_t n) {
    const auto piece = in.first(std::min(n, in.size()));
    in = in.subspan(piece.size());
    return piece;
  };
  while (!in.empty()) {
    const std::uint8_t op = take(1)[0];
    switch (op % 5) {
      case 0:
        client.book.expect(client.nextId++, (op & 0x08) != 0);
        break;
      case 1: {
        const auto arg = take(1);
        const std::uint32_t total = 1 + (arg.empty() ? 0 : arg[0] % 8);
        client.book.start(client.nextId++, "fuzz", total, client.now);
        break;
      }
      case 2: {
        std::vector<std::uint32_t> ids;
        for (const auto& [id, seq] : client.book.sequences) ids.push_back(id);
        for (std::uint32_t id : ids) {
          client.book.sequences.at(id).cancelled = true;
          client.abandon(id, false);
        }
        break;
      }
      case 3: {
        const auto count = take(2);
        const std::size_t n = count.size() < 2 ? in.size() : std::size_t(count[0]) | std::size_t(count[1]) << 8;
        client.serverBytes(take(n));
        break;
      }
      case 4:
        for (auto it = client.book.pending.begin(); it != client.book.pending.end();)
          it = it->second.synchronous && it->second.done ? client.book.pending.erase(it) : std::next(it);
        break;
    }
    client.check();
  }
  return 0;
}
