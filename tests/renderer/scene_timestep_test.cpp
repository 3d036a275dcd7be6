// The scene's "timestep": parsed, printed back, and checked against the
// volume's steps once it is open (scene_volume.h).
#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include "error.h"
#include "scene.h"
#include "scene_errors.h"
#include "scene_volume.h"
#include "volume_test_files.h"

using namespace pvr::core;
using namespace pvr::core::test;
using Catch::Contains;
using nlohmann::json;

namespace {

json sceneWith(const json& timestep) {
  json doc = {{"volume", {{"procedural", "constant-slab"}, {"dims", {2, 2, 2}}}}};
  if (!timestep.is_null()) doc["timestep"] = timestep;
  return doc;
}

// A series sidecar of `steps` raw+JSON volumes in `dir`.
std::string writeSeries(const std::string& dir, int steps) {
  const TestVolume v = testVolume(ScalarType::kUInt8);
  std::string list;
  for (int k = 0; k < steps; ++k) {
    writeRawJson(dir, "s" + std::to_string(k), v, false);
    list += std::string(k ? ", " : "") + "{\"time\": " + std::to_string(k) + ", \"file\": \"s" + std::to_string(k) + ".json\"}";
  }
  const std::string path = dir + "/run.series.json";
  writeText(path, "{\"series\": [" + list + "]}");
  return path;
}

}  // namespace

TEST_CASE("timestep is a 0-based integer, 0 by default, and prints back", "[scene][series]") {
  CHECK(parseScene(sceneWith(nullptr), "").volumes.front().source.timestep == 0);
  const Scene s = parseScene(sceneWith(7), "");
  CHECK(s.volumes.front().source.timestep == 7);
  CHECK(sceneToJson(s)["timestep"] == 7);
  CHECK(parseScene(sceneToJson(s), "").volumes.front().source.timestep == 7);

  CHECK(sceneParseError(sceneWith(-1)) == "timestep: must be in 0..2147483647 (a 0-based step), got -1");
  CHECK(sceneParseError(sceneWith(std::int64_t(1) << 31)) ==
        "timestep: must be in 0..2147483647 (a 0-based step), got 2147483648");
  CHECK(sceneParseError(sceneWith(1.5)) == "timestep: must be an integer, got number 1.5");
  CHECK(sceneParseError(sceneWith("2")) == "timestep: must be an integer, got string \"2\"");
}

TEST_CASE("openSceneVolume checks the timestep against the volume's steps, naming the dataset", "[scene][series]") {
  const std::string dir = scratchDir("scene_timestep");
  VolumeSpec spec;
  spec.file = writeSeries(dir, 3);
  spec.timestep = 2;
  const auto source = openSceneVolume(spec);
  CHECK(source->steps() == 3);

  spec.timestep = 3;
  REQUIRE_THROWS_WITH(openSceneVolume(spec), "timestep 3: run.series.json has 3 time steps (0..2)");
  REQUIRE_THROWS_WITH(checkTimestep(spec, *source), "timestep 3: run.series.json has 3 time steps (0..2)");
  spec.timestep = -1;
  REQUIRE_THROWS_WITH(checkTimestep(spec, *source), Contains("timestep -1"));

  VolumeSpec single;
  single.procedural = "constant-slab";
  single.dims = {2, 2, 2};
  single.timestep = 1;
  REQUIRE_THROWS_WITH(openSceneVolume(single), "timestep 1: constant-slab is a single volume (timestep 0 only)");
  single.timestep = 0;
  CHECK(openSceneVolume(single)->steps() == 1);
}
