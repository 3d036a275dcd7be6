// checkJsonDepth: nesting beyond the limit is refused before any parser
// recurses on it; brackets inside strings do not count.
#include <catch2/catch.hpp>

#include <string>

#include "json_depth.h"

using pvr::proto::checkJsonDepth;
using pvr::proto::ErrorCode;
using pvr::proto::kMaxJsonDepth;

TEST_CASE("JSON nested up to the limit passes, one level more is refused naming where", "[json]") {
  const auto nested = [](int depth) { return std::string(std::size_t(depth), '[') + std::string(std::size_t(depth), ']'); };
  CHECK_FALSE(checkJsonDepth(nested(kMaxJsonDepth), "scene"));
  const auto e = checkJsonDepth(nested(kMaxJsonDepth + 1), "scene");
  REQUIRE(e);
  CHECK(e->code == ErrorCode::kMalformedPayload);
  CHECK(e->text == "scene: JSON nests deeper than 64 levels (at byte 64)");
  // The attack: 100000 levels, 700 KB with objects.
  std::string bomb;
  for (int i = 0; i < 100000; ++i) bomb += "{\"a\":";
  CHECK(checkJsonDepth(bomb, "scene"));
  // Brackets in strings, escaped quotes included, are text.
  CHECK_FALSE(checkJsonDepth("{\"k\": \"" + std::string(200, '[') + "\\\"" + std::string(200, '{') + "\"}", "scene"));
  CHECK_FALSE(checkJsonDepth("{\"camera\": {\"eye\": [1, 2, 3]}, \"volumes\": [{\"name\": \"a\"}]}", "scene"));
}
