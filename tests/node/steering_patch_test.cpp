// The master's steering rules (node/steering_patch.h): a computation volume
// and its parameters are checked against the registry before the ranks see
// them, each error naming what is wrong and the range or names it allows;
// only a patch of "parameters" alone is applied between frames.
#include <catch2/catch.hpp>

#include "steering_patch.h"

namespace {

using namespace pvr;
using namespace pvr::node;

SessionScene computationScene(const nlohmann::json& parameters = nlohmann::json::object()) {
  SessionScene s;
  s.doc = {{"volume", {{"computation", "gray-scott"}, {"dims", {8, 8, 8}}}}, {"parameters", parameters}};
  return s;
}

std::optional<proto::ProtocolError> check(const SessionScene& next, const std::string& patch = "{}") {
  return checkSteering(proto::SetScene{"", patch}, next, "");
}

}  // namespace

TEST_CASE("steering: parameters in range pass, out of range or undeclared are refused naming the range") {
  CHECK_FALSE(check(computationScene()));
  CHECK_FALSE(check(computationScene({{"feed", 0.1}, {"kill", 0}})));
  auto e = check(computationScene({{"feed", 0.2}}));
  REQUIRE(e);
  CHECK(e->code == proto::ErrorCode::kBadArgument);
  CHECK(e->text == "parameters.feed: 0.2 is outside the range [0, 0.1] of gray-scott's parameter 'feed'");
  e = check(computationScene({{"speed", 1}}));
  REQUIRE(e);
  CHECK(e->text ==
        "parameters.speed: gray-scott has no parameter 'speed' (its parameters: feed [0, 0.1], kill [0, 0.1], "
        "du [0, 0.16], dv [0, 0.16], field [0, 1])");
}

TEST_CASE("steering: an unknown computation is refused naming the known ones") {
  SessionScene s = computationScene();
  s.doc["volume"]["computation"] = "navier-stokes";
  const auto e = check(s);
  REQUIRE(e);
  CHECK(e->text == "volume.computation: no computation 'navier-stokes' (known: gray-scott)");
}

TEST_CASE("steering: parameters sent for a volume that is not a computation are refused") {
  SessionScene s;
  s.doc = {{"volume", {{"procedural", "shepp-logan"}, {"dims", {8, 8, 8}}}}, {"parameters", {{"feed", 0.05}}}};
  const auto e = check(s, R"({"parameters": {"feed": 0.05}})");
  REQUIRE(e);
  CHECK(e->text == "parameters: only a computation volume takes parameters (docs/steering.md); "
                   "this scene's volume is a procedural volume");
  // Without a volume nothing is checked yet; without parameters in the patch, nothing is refused.
  CHECK_FALSE(check(SessionScene{}, R"({"parameters": {"feed": 0.05}})"));
  CHECK_FALSE(check(s, R"({"image": {"width": 64}})"));
}

TEST_CASE("steering: only a patch of parameters alone is applied between frames") {
  CHECK(isSteeringPatch(proto::SetScene{"", R"({"parameters": {"feed": 0.05}})"}));
  CHECK_FALSE(isSteeringPatch(proto::SetScene{"", R"({"parameters": {"feed": 0.05}, "image": {"width": 8}})"}));
  CHECK_FALSE(isSteeringPatch(proto::SetScene{"ct.json", R"({"parameters": {"feed": 0.05}})"}));
  CHECK_FALSE(isSteeringPatch(proto::SetScene{"", "not json"}));
  CHECK_FALSE(isSteeringPatch(proto::RenderFrame{}));
}
