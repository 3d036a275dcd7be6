// Requests that would never finish or never fit are refused before any
// work or allocation: a step too small for the domain, a brick larger than
// the host's memory.
#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include "brick.h"
#include "error.h"
#include "scene.h"

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
