// Camera moves (renderer/camera_moves.h): zoom, pan, orbit, standard views
// and the "camera_moves" array, each checked against the identity it keeps.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <string>

#include <nlohmann/json.hpp>

#include "camera.h"
#include "camera_moves.h"
#include "error.h"
#include "scene.h"

using namespace pvr::core;
using nlohmann::json;

namespace {

constexpr double kDeg = std::numbers::pi / 180;

bool near(Vec3 a, Vec3 b, double tolerance = 1e-9) { return length(a - b) < tolerance; }

// A camera on the +x axis looking at (1, 2, 3) from 10 away, up +z.
CameraSpec onPlusX(Projection projection = Projection::kPerspective) {
  CameraSpec c;
  c.projection = projection;
  c.lookAt = {1, 2, 3};
  c.eye = c.lookAt + Vec3{10, 0, 0};
  c.up = {0, 0, 1};
  c.fovYDeg = 40;
  c.height = projection == Projection::kOrthographic ? 6 : 0;
  c.automatic = false;
  return c;
}

// Where the world point p lands in a camera's image, in pixels.
std::pair<double, double> pixelOf(const Camera& camera, Vec3 p) {
  const Vec3 d = p - camera.spec().eye;
  const double depth = dot(d, camera.forward());
  const double x = dot(d, camera.right()), y = dot(d, camera.up());
  if (camera.projection() == Projection::kOrthographic) {
    const double h = camera.spec().height;
    const double w = h * camera.width() / camera.height();
    return {(x / w + 0.5) * camera.width(), (0.5 - y / h) * camera.height()};
  }
  const double t = std::tan(0.5 * camera.spec().fovYDeg * kDeg);
  const double aspect = double(camera.width()) / camera.height();
  return {(x / (depth * t * aspect) + 1) * 0.5 * camera.width(), (1 - y / (depth * t)) * 0.5 * camera.height()};
}

}  // namespace

TEST_CASE("zoomCamera: zoom 2 halves the view height and the tangent of half the field of view",
          "[camera_moves]") {
  // tan(fov'/2) = tan(fov/2) / F: the image is magnified exactly F times.
  const CameraSpec persp = zoomCamera(onPlusX(), 2);
  CHECK(std::tan(0.5 * persp.fovYDeg * kDeg) == Approx(0.5 * std::tan(20 * kDeg)).epsilon(1e-12));
  CHECK(near(persp.eye, onPlusX().eye));
  CHECK_FALSE(persp.automatic);
  const CameraSpec ortho = zoomCamera(onPlusX(Projection::kOrthographic), 2);
  CHECK(ortho.height == Approx(3));
  CHECK(near(ortho.eye, onPlusX().eye));

  // A point off the centre lands twice as far from the image centre.
  const Vec3 p = onPlusX().lookAt + Vec3{0, 0.7, 0.4};
  for (Projection projection : {Projection::kPerspective, Projection::kOrthographic}) {
    const auto [x0, y0] = pixelOf(Camera(onPlusX(projection), 200, 100), p);
    const auto [x1, y1] = pixelOf(Camera(zoomCamera(onPlusX(projection), 2), 200, 100), p);
    CHECK(x1 - 100 == Approx(2 * (x0 - 100)));
    CHECK(y1 - 50 == Approx(2 * (y0 - 50)));
  }
  CHECK_THROWS_AS(zoomCamera(onPlusX(), 0), pvr::Error);
  CHECK_THROWS_AS(zoomCamera(onPlusX(), -1), pvr::Error);
}

TEST_CASE("panCamera: eye and look_at move together, by fractions of the view", "[camera_moves]") {
  for (Projection projection : {Projection::kPerspective, Projection::kOrthographic}) {
    const CameraSpec c0 = onPlusX(projection);
    const CameraSpec c = panCamera(c0, 0.25, -0.5, 2.0);
    // The same shift for both: the view direction is unchanged.
    CHECK(near(c.eye - c0.eye, c.lookAt - c0.lookAt));
    // Looking along -x with up +z, right is +y.
    const double viewHeight = projection == Projection::kOrthographic ? 6 : 2 * 10 * std::tan(20 * kDeg);
    CHECK(near(c.lookAt - c0.lookAt, Vec3{0, 0.25 * viewHeight * 2.0, -0.5 * viewHeight}));
    // The old look_at point moves a quarter of the width left, half the height up on screen.
    const auto [x, y] = pixelOf(Camera(c, 200, 100), c0.lookAt);
    CHECK(x == Approx(100 - 0.25 * 200));
    CHECK(y == Approx(50 - 0.5 * 100));
  }
}

TEST_CASE("azimuthCamera: 90 degrees about +z takes the +x view to the +y view", "[camera_moves]") {
  const CameraSpec c = azimuthCamera(onPlusX(), 90);
  CHECK(near(c.eye, onPlusX().lookAt + Vec3{0, 10, 0}));
  CHECK(near(c.lookAt, onPlusX().lookAt));
  CHECK(near(c.up, {0, 0, 1}));
  // Standard views turn the same way: azimuth 90 of the +x view is the +y view.
  const CameraSpec plusX = standardView(onPlusX(), "+x");
  CHECK(near(azimuthCamera(plusX, 90).eye, standardView(onPlusX(), "+y").eye));
}

TEST_CASE("elevationCamera: raises the eye towards up, refuses to look along it", "[camera_moves]") {
  const CameraSpec c = elevationCamera(onPlusX(), 30);
  const Vec3 toEye = c.eye - c.lookAt;
  CHECK(length(toEye) == Approx(10));
  CHECK(toEye.z == Approx(10 * std::sin(30 * kDeg)));
  CHECK(toEye.x == Approx(10 * std::cos(30 * kDeg)));
  CHECK(std::abs(toEye.y) < 1e-9);
  CHECK(near(elevationCamera(c, -30).eye, onPlusX().eye));
  CHECK_THROWS_WITH(elevationCamera(onPlusX(), 90), Catch::Contains("elevation: would look along the up vector"));
}

TEST_CASE("standardView: the six axis views and iso keep look_at and distance", "[camera_moves]") {
  const CameraSpec base = zoomCamera(onPlusX(), 1.5);
  const struct {
    const char* name;
    Vec3 direction, up;
  } expected[] = {{"+x", {1, 0, 0}, {0, 0, 1}},  {"-x", {-1, 0, 0}, {0, 0, 1}}, {"+y", {0, 1, 0}, {0, 0, 1}},
                  {"-y", {0, -1, 0}, {0, 0, 1}}, {"+z", {0, 0, 1}, {0, 1, 0}},  {"-z", {0, 0, -1}, {0, 1, 0}},
                  {"iso", normalize(Vec3{-1, 1, -1}), {0, 0, 1}}};
  for (const auto& e : expected) {
    INFO(e.name);
    const CameraSpec c = standardView(base, e.name);
    CHECK(near(normalize(c.lookAt - c.eye), e.direction));
    CHECK(length(c.lookAt - c.eye) == Approx(10));
    CHECK(near(c.lookAt, base.lookAt));
    CHECK(near(c.up, e.up));
    CHECK(c.fovYDeg == base.fovYDeg);
    CHECK_NOTHROW(Camera(c, 16, 16));
  }
  CHECK_THROWS_WITH(standardView(base, "top"), Catch::Contains("view: must be one of +x, -x, +y, -y, +z, -z, iso"));
}

TEST_CASE("applyCameraMoves: moves in order from any camera, errors name the entry", "[camera_moves]") {
  const CameraSpec c0 = onPlusX();
  const CameraSpec c = applyCameraMoves(
      c0, json::parse(R"([{"view": "+x"}, {"azimuth": 90}, {"zoom": 2}, {"pan": [0.5, 0]}])"), 1.0);
  // The +x view turned to the +y view (right is then +x), zoomed, panned half a view right.
  CHECK(std::tan(0.5 * c.fovYDeg * kDeg) == Approx(0.5 * std::tan(20 * kDeg)));
  CHECK(near(normalize(c.lookAt - c.eye), {0, 1, 0}));
  const double halfWidth = 0.5 * 2 * 10 * std::tan(0.5 * c.fovYDeg * kDeg);
  CHECK(near(c.lookAt, c0.lookAt + Vec3{halfWidth, 0, 0}));

  // Reset is the automatic camera again: moves never touch automaticCamera.
  GridGeometry grid;
  grid.dims = {16, 24, 32};
  const CameraSpec automatic = automaticCamera(grid, 64, 64);
  const CameraSpec moved = applyCameraMoves(automatic, json::parse(R"([{"zoom": 3}, {"azimuth": 40}])"), 1.0);
  CHECK_FALSE(near(moved.eye, automatic.eye));
  const CameraSpec again = automaticCamera(grid, 64, 64);
  CHECK(near(again.eye, automatic.eye));
  CHECK(again.fovYDeg == 30);

  CHECK_THROWS_WITH(applyCameraMoves(c0, json::parse(R"([{"zoom": 2}, {"zoom": 0}])"), 1.0),
                    Catch::StartsWith("camera_moves[1].zoom: "));
  CHECK_THROWS_WITH(applyCameraMoves(c0, json::parse(R"([{"spin": 2}])"), 1.0),
                    Catch::StartsWith("camera_moves[0].spin: unknown key"));
  CHECK_THROWS_WITH(applyCameraMoves(c0, json::parse(R"([{"elevation": 90}])"), 1.0),
                    Catch::StartsWith("camera_moves[0].elevation: would look along"));
  CHECK_THROWS_WITH(applyCameraMoves(c0, json::parse(R"([{"pan": [1]}])"), 1.0),
                    Catch::StartsWith("camera_moves[0].pan: must be [DX, DY]"));
}
