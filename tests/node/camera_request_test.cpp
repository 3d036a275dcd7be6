// The camera part of a SetScene patch (camera_request.h): what merges as a
// plain patch, and the section made from the camera in force, serially.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include <nlohmann/json.hpp>

#include "camera_request.h"
#include "error.h"

using namespace pvr;
using nlohmann::json;

namespace {

// A volume's automatic camera, and a set camera elsewhere.
core::GridGeometry grid() {
  core::GridGeometry g;
  g.dims = {20, 30, 40};
  return g;
}
core::CameraSpec automatic() { return core::automaticCamera(grid(), 64, 64); }
core::CameraSpec moved() {
  core::CameraSpec c = automatic();
  c.eye = c.eye + core::Vec3{3, 1, 0};
  c.fovYDeg = 12;
  return c;
}

core::CameraSpec parsed(const json& section) { return core::parseCameraSection(section); }

bool same(core::Vec3 a, core::Vec3 b) { return core::length(a - b) < 1e-9; }

}  // namespace

TEST_CASE("takeCameraRequest: camera keys and moves leave the patch", "[camera_request]") {
  json patch = json::parse(R"({"camera": {"fov_y_deg": 20}, "camera_moves": [{"zoom": 2}], "image": {"width": 8}})");
  const node::CameraRequest r = node::takeCameraRequest(patch);
  CHECK(patch == json::parse(R"({"image": {"width": 8}})"));
  CHECK(r.keys == json::parse(R"({"fov_y_deg": 20})"));
  CHECK(r.moves.size() == 1);
  CHECK_FALSE(r.reset);
  json reset = json::parse(R"({"camera": null})");
  CHECK(node::takeCameraRequest(reset).reset);
  json bad = json::parse(R"({"camera": 3})");
  CHECK_THROWS_AS(node::takeCameraRequest(bad), Error);
}

TEST_CASE("mergesIntoDocument: only keys over a set camera, a whole camera or a reset", "[camera_request]") {
  const json automaticDoc = json::object(), setDoc = {{"camera", {{"eye", {0, 0, 5}}, {"look_at", {0, 0, 0}}}}};
  node::CameraRequest fov;
  fov.keys = {{"fov_y_deg", 20}};
  // Today's refusal ("a camera needs eye and look_at") becomes a change of the camera in force.
  CHECK_FALSE(node::mergesIntoDocument(fov, automaticDoc));
  CHECK(node::mergesIntoDocument(fov, setDoc));
  node::CameraRequest whole;
  whole.keys = {{"eye", {0, 0, 5}}, {"look_at", {0, 0, 0}}};
  CHECK(node::mergesIntoDocument(whole, automaticDoc));
  node::CameraRequest reset;
  reset.reset = true;
  CHECK(node::mergesIntoDocument(reset, setDoc));
  reset.moves = json::parse(R"([{"zoom": 2}])");
  CHECK_FALSE(node::mergesIntoDocument(reset, setDoc));
}

TEST_CASE("cameraSectionAfter: -fov alone changes the camera in force, reset returns the automatic one",
          "[camera_request]") {
  node::CameraRequest fov;
  fov.keys = {{"fov_y_deg", 20}};
  const core::CameraSpec c = parsed(node::cameraSectionAfter(fov, automatic(), automatic(), 1.0));
  CHECK(same(c.eye, automatic().eye));
  CHECK(same(c.lookAt, automatic().lookAt));
  CHECK(c.fovYDeg == 20);

  // Reset then nothing: the automatic camera, whatever was in force.
  node::CameraRequest reset;
  reset.reset = true;
  const core::CameraSpec back = parsed(node::cameraSectionAfter(reset, moved(), automatic(), 1.0));
  CHECK(same(back.eye, automatic().eye));
  CHECK(same(back.up, automatic().up));
  CHECK(back.fovYDeg == automatic().fovYDeg);

  // Reset then zoom 2: the automatic camera, zoomed.
  reset.moves = json::parse(R"([{"zoom": 2}])");
  const core::CameraSpec zoomed = parsed(node::cameraSectionAfter(reset, moved(), automatic(), 1.0));
  CHECK(same(zoomed.eye, automatic().eye));
  CHECK(std::tan(zoomed.fovYDeg * std::numbers::pi / 360) ==
        Approx(0.5 * std::tan(automatic().fovYDeg * std::numbers::pi / 360)));

  // Orthographic alone: the view height the perspective view has at look_at.
  node::CameraRequest ortho;
  ortho.keys = {{"projection", "orthographic"}};
  const core::CameraSpec o = parsed(node::cameraSectionAfter(ortho, automatic(), automatic(), 1.0));
  CHECK(o.projection == core::Projection::kOrthographic);
  CHECK(o.height == Approx(2 * core::length(automatic().lookAt - automatic().eye) * std::tan(std::numbers::pi / 12)));

  // A refused move refuses the whole request, naming it.
  node::CameraRequest bad;
  bad.moves = json::parse(R"([{"view": "top"}])");
  CHECK_THROWS_WITH(node::cameraSectionAfter(bad, automatic(), automatic(), 1.0),
                    Catch::StartsWith("camera_moves[0].view: must be one of"));
}
