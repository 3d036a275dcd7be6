// RenderRotation's cameras (rotation.h), serially.
#include <catch2/catch.hpp>

#include "error.h"
#include "rotation.h"

using namespace pvr;

namespace {

core::CameraSpec camera() {
  core::CameraSpec c;
  c.lookAt = {1, 2, 3};
  c.eye = {1, -8, 3};  // 10 along -y from look_at
  c.up = {0, 0, 1};
  c.automatic = false;
  return c;
}

}  // namespace

TEST_CASE("eye and up turn about look_at, frame k of a request starting at s is step s + k") {
  // Quarter turns about +z: the eye goes from -y to +x of look_at; up stays.
  const node::Rotation r(camera(), {{0, 0, 2}, 1, 3, 4});
  REQUIRE(r.frames() == 3);
  const core::CameraSpec first = r.camera(0);  // step 1: 90 degrees
  CHECK(first.eye.x == Approx(11).margin(1e-12));
  CHECK(first.eye.y == Approx(2).margin(1e-12));
  CHECK(first.eye.z == Approx(3).margin(1e-12));
  CHECK(first.lookAt.x == 1);
  CHECK(first.up.z == Approx(1));
  const core::CameraSpec half = r.camera(1);  // step 2: 180 degrees
  CHECK(half.eye.y == Approx(12).margin(1e-12));
  // About +x, the up vector turns too: a quarter turn takes +z to -y.
  const core::CameraSpec tilted = node::Rotation(camera(), {{1, 0, 0}, 1, 1, 4}).camera(0);
  CHECK(tilted.up.y == Approx(-1).margin(1e-12));
  CHECK(tilted.eye.z == Approx(-7).margin(1e-12));
}

TEST_CASE("a rotation no frames answer is refused") {
  CHECK_THROWS_AS(node::Rotation(camera(), {{0, 1, 0}, 0, 5, 0}), Error);
  CHECK_THROWS_AS(node::Rotation(camera(), {{0, 1, 0}, 5, 4, 10}), Error);
  CHECK_THROWS_AS(node::Rotation(camera(), {{0, 0, 0}, 0, 1, 10}), Error);
  CHECK_THROWS_AS(node::Rotation(camera(), {{0, 1, 0}, 0, std::int32_t(proto::kMaxRotationFrames), 10}), Error);
  CHECK(node::Rotation(camera(), {{0, 1, 0}, 0, std::int32_t(proto::kMaxRotationFrames) - 1, 10}).frames() ==
        int(proto::kMaxRotationFrames));
}
