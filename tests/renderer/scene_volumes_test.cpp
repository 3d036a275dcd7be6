// The scene's "volumes" (several volumes, each with its transfer function),
// its single-volume form, computation volumes and "parameters": parsed,
// printed back, and refused with key paths.
#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include "error.h"
#include "scene.h"
#include "scene_errors.h"
#include "scene_volume.h"

using namespace pvr::core;
using namespace pvr::core::test;
using Catch::Contains;
using nlohmann::json;

namespace {

json slab(const char* name) {
  return {{"name", name}, {"procedural", "constant-slab"}, {"dims", {4, 4, 4}}};
}

}  // namespace

TEST_CASE("a volumes list keeps each volume's name, source, transfer function and visibility", "[scene][volumes]") {
  json ct = slab("ct");
  ct["transfer_function"] = {{"points", {{0, 1, 0, 0, 0.5}}}, {"unit_distance", 2}};
  json pet = slab("pet");
  pet["dims"] = {8, 4, 2};
  pet["spacing"] = {0.5, 1, 2};
  pet["visible"] = false;
  const Scene s = parseScene({{"volumes", {ct, pet}}, {"timestep", 0}}, "");
  REQUIRE(s.volumes.size() == 2);
  CHECK(s.volumes[0].name == "ct");
  CHECK(s.volumes[0].visible);
  REQUIRE(s.volumes[0].transfer.points.size() == 1);
  CHECK(s.volumes[0].transfer.points[0].r == 1);
  CHECK(s.volumes[0].transfer.unitDistance == 2);
  CHECK(s.volumes[1].name == "pet");
  CHECK_FALSE(s.volumes[1].visible);
  CHECK(s.volumes[1].source.dims == IVec3{8, 4, 2});
  REQUIRE(s.volumes[1].source.spacing);
  CHECK(s.volumes[1].source.spacing->z == 2);
  // A volume without a transfer function takes the default one.
  CHECK(s.volumes[1].transfer.points.size() == rampTransfer(0, 1).points.size());

  const json printed = sceneToJson(s);
  CHECK_FALSE(printed.contains("volume"));
  CHECK_FALSE(printed.contains("transfer_function"));
  const Scene back = parseScene(printed, "");
  REQUIRE(back.volumes.size() == 2);
  CHECK(back.volumes[1].name == "pet");
  CHECK_FALSE(back.volumes[1].visible);
  CHECK(back.volumes[0].transfer.unitDistance == 2);
  CHECK(sceneToJson(back) == printed);
}

TEST_CASE("the single volume form is the one-element list named volume, and prints as it was", "[scene][volumes]") {
  const json doc = {{"volume", {{"procedural", "constant-slab"}, {"dims", {4, 4, 4}}}},
                    {"transfer_function", {{"points", {{0, 1, 1, 1, 0.25}}}}}};
  const Scene s = parseScene(doc, "");
  REQUIRE(s.volumes.size() == 1);
  CHECK(s.volumes[0].name == "volume");
  CHECK(s.volumes[0].visible);
  CHECK(s.volumes[0].transfer.points[0].opacity == 0.25);
  const json printed = sceneToJson(s);
  CHECK(printed.contains("volume"));
  CHECK(printed.contains("transfer_function"));
  CHECK_FALSE(printed.contains("volumes"));
  // One named volume is a list, so the name survives the round trip.
  const Scene named = parseScene({{"volumes", {slab("ct")}}}, "");
  CHECK(parseScene(sceneToJson(named), "").volumes[0].name == "ct");
}

TEST_CASE("the timestep applies to every volume", "[scene][volumes]") {
  const Scene s = parseScene({{"volumes", {slab("a"), slab("b")}}, {"timestep", 3}}, "");
  CHECK(s.volumes[0].source.timestep == 3);
  CHECK(s.volumes[1].source.timestep == 3);
}

TEST_CASE("bad volumes lists are refused with their key path", "[scene][volumes]") {
  const json one = {{"procedural", "constant-slab"}};
  CHECK(sceneParseError({{"volume", one}, {"volumes", {slab("a")}}}) ==
        "volumes: give \"volume\" (one volume) or \"volumes\" (several), not both");
  CHECK(sceneParseError({{"volumes", {slab("a")}}, {"transfer_function", {{"points", {{0, 1, 1, 1, 1}}}}}}) ==
        "transfer_function: a \"volumes\" scene gives each volume its own transfer_function");
  CHECK(sceneParseError({{"volumes", json::array()}}) == "volumes: needs at least one volume");
  CHECK(sceneParseError({{"volumes", json::object()}}) == "volumes: must be an array of volumes, got object {}");
  CHECK(sceneParseError({{"volumes", {slab("a"), slab("a")}}}) ==
        "volumes[1].name: 'a' names an earlier volume too; names must be unique");
  CHECK(sceneParseError({{"volumes", {one}}}) == "volumes[0].name: missing (every volume of \"volumes\" has a name)");
  json unnamed = slab("");
  CHECK(sceneParseError({{"volumes", {unnamed}}}) == "volumes[0].name: must not be empty");
  json typo = slab("a");
  typo["visble"] = true;
  CHECK_THAT(sceneParseError({{"volumes", {slab("b"), typo}}}), Contains("volumes[1].visble: unknown key"));
  json badTf = slab("a");
  badTf["transfer_function"] = {{"points", json::array()}};
  CHECK(sceneParseError({{"volumes", {badTf}}}) == "volumes[0].transfer_function.points: needs at least one point");
  json badVisible = slab("a");
  badVisible["visible"] = 1;
  CHECK_THAT(sceneParseError({{"volumes", {badVisible}}}), Contains("volumes[0].visible: must be"));
}

TEST_CASE("a computation volume and its parameters parse and print back", "[scene][steering]") {
  const json doc = {{"volume", {{"computation", "gray_scott"}, {"dims", {32, 32, 16}}}},
                    {"parameters", {{"feed", 0.055}, {"kill", 0.062}}}};
  const Scene s = parseScene(doc, "");
  CHECK(s.volumes[0].source.computation == "gray_scott");
  CHECK(s.volumes[0].source.procedural.empty());
  CHECK(s.volumes[0].source.dims == IVec3{32, 32, 16});
  REQUIRE(s.parameters.size() == 2);
  CHECK(s.parameters.at("feed") == 0.055);
  const json printed = sceneToJson(s);
  CHECK(printed["volume"]["computation"] == "gray_scott");
  CHECK(printed["parameters"]["kill"] == 0.062);
  const Scene back = parseScene(printed, "");
  CHECK(back.volumes[0].source.computation == "gray_scott");
  CHECK(back.parameters == s.parameters);
  // No parameters: the key is absent.
  CHECK_FALSE(sceneToJson(parseScene({{"volume", {{"computation", "x"}}}}, "")).contains("parameters"));

  CHECK(sceneParseError({{"volume", {{"computation", ""}}}}) == "volume.computation: must not be empty");
  CHECK(sceneParseError({{"volume", {{"computation", "x"}}}, {"parameters", {{"feed", "a"}}}}) ==
        "parameters.feed: must be a number, got string \"a\"");
  CHECK(sceneParseError({{"volume", {{"computation", "x"}}}, {"parameters", {1, 2}}}) ==
        "parameters: must be an object {name: number, ...}, got array [1,2]");
  // A computation is the ranks' to run: opening it as a volume says so.
  try {
    openSceneVolume(s.volumes[0].source);
    FAIL("a computation volume opened");
  } catch (const pvr::Error& e) {
    CHECK_THAT(e.what(), Contains("volume.computation 'gray_scott': a computation runs on the ranks"));
  }
}

namespace pvr::core {

// resolveDefaults over several grids: each volume's unit distance is its
// own voxel, the step half the smallest voxel of all, the automatic camera
// looks at the centre of the union of the domains.
TEST_CASE("several volumes resolve their own unit distance, one step and a camera over their union",
          "[scene]") {
  Scene s;
  s.volumes.resize(2);
  GridGeometry a, b;
  a.dims = {10, 10, 10};
  b.dims = {5, 5, 5};
  b.spacing = {0.5, 0.5, 0.5};
  b.origin = {20, 0, 0};
  s.shading.automatic = true;
  resolveDefaults(s, std::vector<GridGeometry>{a, b});
  CHECK(s.volumes[0].transfer.unitDistance == 1.0);
  CHECK(s.volumes[1].transfer.unitDistance == 0.5);
  CHECK(s.sampling.step == 0.25);
  CHECK_FALSE(s.camera.automatic);
  CHECK(s.camera.lookAt.x == 11.0);
  CHECK(s.camera.lookAt.y == 4.5);
  CHECK(s.camera.lookAt.z == 4.5);
  CHECK(s.shading.enabled);
}

}  // namespace pvr::core
