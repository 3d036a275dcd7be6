// Runtime settings (runtime_settings.h) and the one list of decompositions
// (distribute.h), serially.
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "runtime_settings.h"
#include "strategy.h"

using namespace pvr;
using nlohmann::json;

TEST_CASE("settingsFrom reads every key over the defaults") {
  const auto s = node::settingsFrom(json::parse(
      R"({"strategy": "radix-k", "decomposition": "balanced", "rebalance_threshold": 1.5,
          "pixels": "rgb8", "compression": "none", "threads": 3, "cachemem": 12})"));
  CHECK(s.strategy == "radix-k");
  CHECK(s.decomposition == node::Decomposition::kBalanced);
  CHECK(s.rebalanceThreshold == 1.5);
  CHECK(s.format == proto::PixelFormat::kRgb8);
  CHECK(s.compression == proto::Compression::kNone);
  CHECK(s.threads == 3);
  CHECK(s.cacheMegabytes == 12);
  CHECK(node::cacheBudgetBytes(s) == 12u << 20);
  CHECK(node::settingsFrom(json::object()) == node::RuntimeSettings{});
}

TEST_CASE("settingsFrom refuses an unknown strategy with every registered one") {
  try {
    node::settingsFrom(json{{"strategy", "binary-swapp"}});
    FAIL("accepted");
  } catch (const Error& e) {
    CHECK(e.code() == ErrorCode::kInvalidArgument);
    const std::string text = e.what();
    CHECK_THAT(text, Catch::StartsWith("runtime.strategy: "));
    for (const auto& entry : composite::strategies()) CHECK_THAT(text, Catch::Contains(std::string(entry.name)));
  }
}

TEST_CASE("settingsFrom names the key of a wrong value, type or name") {
  const auto refusal = [](const json& j) {
    try {
      node::settingsFrom(j);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  CHECK_THAT(refusal({{"decomposition", "octree"}}), Catch::Contains("runtime.decomposition") && Catch::Contains("kd, balanced, slabs"));
  CHECK_THAT(refusal({{"threads", "four"}}), Catch::Contains("runtime.threads"));
  CHECK_THAT(refusal({{"threads", 0}}), Catch::Contains("runtime.threads"));
  CHECK_THAT(refusal({{"pixels", 8}}), Catch::Contains("runtime.pixels: must be a string"));
  CHECK_THAT(refusal({{"compression", "lz4"}}), Catch::Contains("none, rle, zlib"));
  CHECK_THAT(refusal({{"rebalance_threshold", 0.5}}), Catch::Contains("runtime.rebalance_threshold"));
  CHECK_THAT(refusal({{"cachemem", -1}}), Catch::Contains("runtime.cachemem: must be an integer number of MB"));
  CHECK_THAT(refusal({{"cachemem", 1.5}}), Catch::Contains("runtime.cachemem"));
  CHECK_THAT(refusal({{"colour", 1}}), Catch::Contains("runtime.colour: unknown key"));
  CHECK_THAT(refusal(json::array()), Catch::Contains("runtime: must be an object"));
}

TEST_CASE("every decomposition reads back from its name") {
  REQUIRE(node::decompositions().size() == 3);
  for (const auto& d : node::decompositions()) {
    CHECK(node::decompositionName(d.value) == d.name);
    CHECK(node::decompositionNamed(d.name) == d.value);
  }
  CHECK_THROWS_WITH(node::decompositionNamed("octree"), Catch::Contains("known: kd, balanced, slabs"));
}
