// Requests that would never finish or never fit are refused before any
// work or allocation: a step too small for the domain, a brick larger than
// the host's memory.
#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include "brick.h"
#include "error.h"
#include "io/json_file.h"
#include "scene.h"
#include "test_files.h"

using namespace pvr::core;
using Catch::Contains;

TEST_CASE("a step that needs more than kMaxSamplesPerRay samples across the domain is refused", "[scene][limits]") {
  GridGeometry grid;
  grid.dims = {101, 101, 101};  // diagonal sqrt(3) * 100
  for (const double step : {1e-9, 1e-20}) {
    Scene s = parseScene(nlohmann::json{{"volume", {{"procedural", "constant-slab"}}}, {"sampling", {{"step", step}}}}, "");
    try {
      resolveDefaults(s, grid);
      FAIL("step " << step << " accepted");
    } catch (const pvr::Error& e) {
      CHECK(e.code() == pvr::ErrorCode::kInvalidArgument);
      CHECK_THAT(e.what(), Contains("sampling.step: ") && Contains("samples across the domain's diagonal (173.205") &&
                               Contains("at most 1048576 are allowed, so the step must be at least 0.000165"));
    }
  }
  // The smallest allowed step itself resolves.
  Scene s = parseScene(nlohmann::json{{"volume", {{"procedural", "constant-slab"}}}, {"sampling", {{"step", 0.000166}}}}, "");
  CHECK_NOTHROW(resolveDefaults(s, grid));
}

TEST_CASE("a brick larger than the host's memory is refused before it is allocated", "[brick][limits]") {
  GridGeometry grid;
  grid.dims = {1 << 20, 1 << 20, 1 << 20};  // 2^60 nodes
  const NodeBox all = grid.allNodes();
  try {
    Brick brick(grid, ScalarType::kFloat32, all, all);
    FAIL("a 4 EiB brick was allocated");
  } catch (const pvr::Error& e) {
    CHECK(e.code() == pvr::ErrorCode::kUnsupported);
    CHECK_THAT(e.what(), Contains("brick [0..1048575]x[0..1048575]x[0..1048575] of float32 needs 4294967296.0 GiB; "
                                  "this host has ") &&
                             Contains("GiB of memory (use more ranks or hosts)"));
  }
  CHECK_THROWS_AS(Brick::forOverwrite(grid, ScalarType::kUInt8, all, all), pvr::Error);
}

// n arrays, one inside the other, as the value of a scene's "volume".
static std::string sceneNestedArrays(int n) {
  return "{\"volume\": " + std::string(std::size_t(n), '[') + std::string(std::size_t(n), ']') + "}";
}

TEST_CASE("a scene file nesting deeper than kMaxJsonDepth is refused before the stack overflows", "[scene][limits]") {
  // Found by fuzz/scene_parser_fuzz.cpp: 100000 nested arrays (200 KB)
  // crashed pvr-render with a stack overflow when the scene's error message
  // printed the value (describeValue -> nlohmann's recursive dump).
  const std::string dir = pvr::core::test::scratchDir("deep_scene");
  const std::string path = dir + "/deep.json";
  pvr::core::test::writeText(path, sceneNestedArrays(100000));
  try {
    loadSceneFile(path);
    FAIL("a 100000-deep scene was accepted");
  } catch (const pvr::Error& e) {
    CHECK(e.code() == pvr::ErrorCode::kBadFile);
    CHECK_THAT(e.what(), Contains(path + ": nests objects and arrays deeper than 64 levels"));
  }
  // The limit counts the document's own object: 64 levels pass the reader
  // (and are refused by the scene parser for what they are), 65 do not.
  CHECK_THROWS_WITH(parseScene(parseJsonText(sceneNestedArrays(63), "s.json"), ""),
                    Contains("volume: must be an object"));
  CHECK_THROWS_WITH(parseJsonText(sceneNestedArrays(64), "s.json"),
                    Contains("s.json: nests objects and arrays deeper than 64 levels"));
}

TEST_CASE("a scene file with a number too large for a double is refused as invalid JSON", "[scene][limits]") {
  // Found by fuzz/scene_parser_fuzz.cpp: nlohmann reports "1e400" as
  // out_of_range, not parse_error, and it escaped readJsonFile as no
  // pvr::Error (pvr-render ended with std::terminate).
  const std::string dir = pvr::core::test::scratchDir("huge_number_scene");
  const std::string path = dir + "/huge.json";
  pvr::core::test::writeText(path, R"({"volume": {"procedural": "constant-slab"}, "sampling": {"step": 1e400}})");
  try {
    loadSceneFile(path);
    FAIL("a scene with 1e400 was accepted");
  } catch (const pvr::Error& e) {
    CHECK(e.code() == pvr::ErrorCode::kBadFile);
    CHECK_THAT(e.what(), Contains(path + ": not valid JSON: ") && Contains("number overflow parsing '1e400'"));
  }
}

TEST_CASE("a scene error quoting a key or name masks its control bytes", "[scene][limits]") {
  // Found by fuzz/scene_parser_fuzz.cpp: the key "\u0000" made the message
  // "\0: unknown key ...", empty where it is read as a C string (what(), the
  // wire's error text); an escape sequence in a key or a procedural name went
  // raw to the terminal or log that shows the message.
  const auto messageOf = [](const nlohmann::json& doc) -> std::string {
    try {
      parseScene(doc, "");
    } catch (const pvr::Error& e) {
      return e.what();
    }
    return "accepted";
  };
  CHECK(messageOf({{std::string("\0", 1), 1}}) ==
        "?: unknown key (known: volume, volumes, timestep, transfer_function, parameters, camera, image, sampling, "
        "shading)");
  CHECK_THAT(messageOf({{"volume", {{"procedural", "\x1b[2J"}}}}),
             Contains("volume.procedural: unknown procedural volume '?[2J' (known: "));
}
