// The Tcl-free part of pvrsh's reply handling: ReplyBook (which request a
// server message answers, and the records kept of it) and FrameIntake
// (bytes into messages, frames too large skipped). hostile_server.test
// drives the same code through a session and a fake server.
#include <catch2/catch.hpp>

#include "frame_intake.h"
#include "reply_book.h"

using namespace pvr;
using namespace pvr::tcl;

namespace {

proto::Decoded decoded(proto::Message m, std::uint32_t id, bool final) {
  proto::Decoded d{std::move(m), {id, std::uint16_t(final ? proto::kFlagFinal : 0)}, 0};
  return d;
}

proto::ImageFrame frame(std::uint32_t number) {
  proto::ImageFrame f;
  f.frameNumber = number;
  f.width = f.height = 1;
  f.pixels = {1, 2, 3};
  return f;
}

}  // namespace

// Issue 15, finding 15: every frame copied the whole sequence's records
// into a "latest sequence" (40000 frames took 18.3 s). Now the latest
// sequence in flight is that sequence itself, so a frame costs one record.
TEST_CASE("ReplyBook keeps a sequence's frame records in one place: the latest sequence in flight is no copy") {
  ReplyBook book;
  const auto t0 = Clock::now();
  book.start(7, "rotate", 40000, t0);
  for (std::uint32_t k = 0; k < 40000; ++k) {
    const Arrival a = book.route(decoded(frame(k), 7, k + 1 == 40000), t0);
    REQUIRE(a.kind == Arrival::Kind::kFrame);
    REQUIRE(a.complete == (k + 1 == 40000));
  }
  CHECK(&book.latest() == &book.sequences.at(7));
  CHECK(book.latest().frames.size() == 40000);
  // Finishing moves the records; nothing is copied there either.
  const FrameRecord* records = book.sequences.at(7).frames.data();
  auto seq = book.finish(7);
  REQUIRE(seq);
  book.remember(std::move(*seq));
  CHECK(book.latest().frames.data() == records);
  CHECK(book.latest().id == 7);
  CHECK_FALSE(book.busy());
}

TEST_CASE("ReplyBook drops the answers of an abandoned sequence up to its last one") {
  ReplyBook book;
  book.start(3, "rotate", 5, Clock::now());
  book.route(decoded(frame(0), 3, false), Clock::now());
  auto seq = book.finish(3);
  book.drop(3);
  CHECK(book.route(decoded(frame(1), 3, false), Clock::now()).kind == Arrival::Kind::kIgnored);
  CHECK(book.dropped.count(3) == 1);
  CHECK(book.route(decoded(proto::ErrorMessage{proto::ErrorCode::kCancelled, "stopped"}, 3, true), Clock::now()).kind ==
        Arrival::Kind::kIgnored);
  CHECK(book.dropped.empty());
}

TEST_CASE("ReplyBook: a server Close is news about the session, whatever socket state follows") {
  ReplyBook book;
  const Arrival a = book.route(decoded(proto::Close{"maintenance"}, 0, true), Clock::now());
  CHECK(a.kind == Arrival::Kind::kClosed);
  CHECK(a.reason == "maintenance");
}

TEST_CASE("FrameIntake skips a frame over its limit, reports it, and decodes the frames after it") {
  FrameIntake intake;
  proto::CatalogReply big{{{std::string((4u << 20) + 1, 'd'), 1}}};
  auto bytes = proto::encode(big, 5, proto::kFlagFinal);
  const auto ok = proto::encode(proto::Ok{}, 6, proto::kFlagFinal);
  bytes.insert(bytes.end(), ok.begin(), ok.end());
  // In two pieces: the refusal comes with the header, the rest is skipped.
  intake.feed(std::span(bytes).first(100));
  CHECK(intake.inFrame());
  auto first = intake.pop();
  REQUIRE(first);
  const auto* refused = std::get_if<FrameIntake::Refused>(&*first);
  REQUIRE(refused);
  CHECK(refused->header.requestId == 5);
  CHECK(refused->type == "CatalogReply");
  CHECK(refused->error.code == proto::ErrorCode::kFrameTooLarge);
  intake.feed(std::span(bytes).subspan(100));
  CHECK_FALSE(intake.inFrame());
  auto second = intake.pop();
  REQUIRE(second);
  REQUIRE(std::holds_alternative<proto::Decoded>(*second));
  CHECK(std::get<proto::Decoded>(*second).info.requestId == 6);
  CHECK_FALSE(intake.error());
}

TEST_CASE("FrameIntake: half a frame is a frame in progress, and a broken payload ends the stream") {
  FrameIntake intake;
  const auto ok = proto::encode(proto::Close{"bye"}, 0, proto::kFlagFinal);
  intake.feed(std::span(ok).first(ok.size() - 1));
  CHECK(intake.inFrame());
  CHECK_FALSE(intake.pop());
  CHECK(intake.endOfStream()->code == proto::ErrorCode::kTruncatedFrame);

  FrameIntake broken;
  auto bad = proto::encode(proto::Close{"bye"}, 0, proto::kFlagFinal);
  bad[16] = 0xff;  // the reason's length now runs past the payload
  broken.feed(bad);
  CHECK_FALSE(broken.pop());
  REQUIRE(broken.error());
  CHECK(broken.error()->code == proto::ErrorCode::kMalformedPayload);
}
