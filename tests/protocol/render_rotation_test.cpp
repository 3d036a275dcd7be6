// RenderRotation::check: the one rule for rotation requests, which decoding
// enforces and a client may call before sending.
#include <catch2/catch.hpp>

#include <limits>

#include "pvr_protocol.h"

using namespace pvr::proto;

namespace {

std::optional<ErrorCode> codeOf(const RenderRotation& rotation, const Limits& limits = {}) {
  if (auto problem = rotation.check(limits)) return problem->code;
  return std::nullopt;
}

}  // namespace

TEST_CASE("rotation check: the paper's request and single frames pass") {
  CHECK_FALSE(codeOf(RenderRotation{{0, 1, 0}, 15, 59, 60}));  // paper 003: 45 frames
  CHECK(RenderRotation{{0, 1, 0}, 15, 59, 60}.frameCount() == 45);
  CHECK_FALSE(codeOf(RenderRotation{{1, 0, 0}, -3, -3, 1}));  // one frame, negative step
  CHECK_FALSE(codeOf(RenderRotation{{0, 0, 2.5}, 0, 0, 1}));  // axis need not be unit length
}

TEST_CASE("rotation check: steps per turn, order of start and end") {
  const auto zeroSteps = RenderRotation{{0, 1, 0}, 0, 3, 0}.check({});
  REQUIRE(zeroSteps);
  CHECK(zeroSteps->code == ErrorCode::kBadArgument);
  CHECK_THAT(zeroSteps->text, Catch::Contains("steps 0 to 3") && Catch::Contains("0 steps per turn"));
  const auto backwards = RenderRotation{{0, 1, 0}, 5, 4, 60}.check({});
  REQUIRE(backwards);
  CHECK(backwards->code == ErrorCode::kBadArgument);
  CHECK_THAT(backwards->text, Catch::Contains("steps 5 to 4"));
}

TEST_CASE("rotation check: at most kMaxRotationFrames frames, counted without overflow") {
  constexpr auto kMost = std::int32_t(kMaxRotationFrames);
  CHECK_FALSE(codeOf(RenderRotation{{0, 1, 0}, 0, kMost - 1, 60}));
  CHECK(RenderRotation{{0, 1, 0}, 0, kMost - 1, 60}.frameCount() == kMaxRotationFrames);
  const auto over = RenderRotation{{0, 1, 0}, 0, kMost, 60}.check({});
  REQUIRE(over);
  CHECK(over->code == ErrorCode::kLimitExceeded);
  CHECK_THAT(over->text, Catch::Contains(std::to_string(kMost + 1) + " frames") &&
                             Catch::Contains("limit of " + std::to_string(kMost) + " frames per request"));
  // The whole int32 range is 2^32 frames: it must not wrap to a small count.
  CHECK(codeOf(RenderRotation{{0, 1, 0}, std::numeric_limits<std::int32_t>::min(),
                              std::numeric_limits<std::int32_t>::max(), 60}) == ErrorCode::kLimitExceeded);
  // The limit comes from Limits, whose default is the named constant.
  Limits tight;
  tight.maxRotationFrames = 10;
  CHECK_FALSE(codeOf(RenderRotation{{0, 1, 0}, 0, 9, 60}, tight));
  CHECK(codeOf(RenderRotation{{0, 1, 0}, 0, 10, 60}, tight) == ErrorCode::kLimitExceeded);
}

TEST_CASE("rotation check: the axis is finite and nonzero, and has a finite nonzero length") {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const std::array<double, 3>& axis : std::vector<std::array<double, 3>>{
           {0, 0, 0}, {-0.0, 0, 0}, {nan, 1, 0}, {inf, 0, 0}, {0, -inf, 1}, {1.5e308, 1.5e308, 0}}) {
    INFO("axis " << axis[0] << " " << axis[1] << " " << axis[2]);
    CHECK(codeOf(RenderRotation{axis, 0, 1, 4}) == ErrorCode::kBadArgument);
  }
  // Tiny and huge components still give a unit vector when divided by hypot.
  CHECK_FALSE(codeOf(RenderRotation{{1e-300, 0, 1e-310}, 0, 1, 4}));
  CHECK_FALSE(codeOf(RenderRotation{{1e308, -1e308, 1e308}, 0, 1, 4}));
}

TEST_CASE("the decoder enforces the rotation check with its code, the encoder does not") {
  const auto bad = encode(RenderRotation{{0, 1, 0}, 0, 3, 0}, 4);  // a sender may write anything
  const auto result = decodeFrame(bad);
  REQUIRE(std::holds_alternative<ProtocolError>(result));
  CHECK(std::get<ProtocolError>(result).code == ErrorCode::kBadArgument);
  CHECK_THAT(std::get<ProtocolError>(result).text, Catch::StartsWith("RenderRotation payload: rotation of"));

  // A receiver with a tighter frame limit refuses what the default accepts.
  const auto ten = encode(RenderRotation{{0, 1, 0}, 0, 10, 60}, 5);
  CHECK(std::holds_alternative<Decoded>(decodeFrame(ten)));
  Limits tight;
  tight.maxRotationFrames = 10;
  const auto refused = decodeFrame(ten, tight);
  REQUIRE(std::holds_alternative<ProtocolError>(refused));
  CHECK(std::get<ProtocolError>(refused).code == ErrorCode::kLimitExceeded);
}
