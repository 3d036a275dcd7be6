// Procedural volumes: the grid they sit on, their values and symmetries,
// and that a box generated alone equals the same box cut from the whole.
#include <catch2/catch.hpp>

#include "volume_test_files.h"

using namespace pvr::core;
using Catch::Contains;

TEST_CASE("procedural grids span [-1,1] on the longest axis, centred at 0", "[io]") {
  const auto src = openProcedural("marschner-lobb", {65, 33, 17});
  const GridGeometry& g = src->grid();
  CHECK(g.spacing == Vec3{2.0 / 64, 2.0 / 64, 2.0 / 64});
  CHECK(g.domainMin().x == Approx(-1));
  CHECK(g.domainMax().x == Approx(1));
  CHECK(g.domainMin().y == Approx(-0.5));
  CHECK(g.domainMax().z == Approx(0.25));
  CHECK(g.center().x == Approx(0).margin(1e-15));
  CHECK(src->type() == ScalarType::kFloat32);
  CHECK(src->canReadPartially());
  CHECK_THAT(src->describe(), Contains("marschner-lobb") && Contains("65x33x17 float32"));

  // Given spacing: origin = -(dims - 1) * spacing / 2.
  const auto aniso = openProcedural("shepp-logan", {11, 21, 5}, Vec3{0.1, 0.05, 0.5});
  CHECK(aniso->grid().origin.x == Approx(-0.5));
  CHECK(aniso->grid().origin.y == Approx(-0.5));
  CHECK(aniso->grid().origin.z == Approx(-1.0));

  // One node: a point at 0.
  const auto point = openProcedural("constant-slab", {1, 1, 1});
  CHECK(point->grid().origin == Vec3{0, 0, 0});
  CHECK(point->readAll().valueAt({0, 0, 0}) == 1.0);
}

TEST_CASE("procedural values lie in [0,1], the constant slab is 1 everywhere", "[io]") {
  for (const std::string& name : proceduralNames()) {
    INFO(name);
    const Brick b = openProcedural(name, {24, 20, 16})->readAll();
    CHECK(b.valueRange().min >= 0.0);
    CHECK(b.valueRange().max <= 1.0);
    CHECK(b.valueRange().nonFinite == 0);
    if (name != "constant-slab") CHECK(b.valueRange().max > b.valueRange().min + 0.1);
  }
  const ValueRange r = openProcedural("constant-slab", {5, 6, 7})->readAll().valueRange();
  CHECK(r.min == 1.0);
  CHECK(r.max == 1.0);
}

TEST_CASE("Marschner-Lobb has its closed-form values and radial symmetry", "[io]") {
  // On the z axis r = 0, rho_r = cos(12 pi) = 1: rho = (1 - sin(pi z / 2) + 0.5) / 2.5.
  CHECK(proceduralValue("marschner-lobb", {0, 0, 0}) == Approx(0.6));
  CHECK(proceduralValue("marschner-lobb", {0, 0, 1}) == Approx(0.2));
  CHECK(proceduralValue("marschner-lobb", {0, 0, -1}) == Approx(1.0));
  for (double x : {0.1, 0.37, 0.9})
    for (double y : {-0.2, 0.55})
      for (double z : {-0.7, 0.3}) {
        const double v = proceduralValue("marschner-lobb", {x, y, z});
        CHECK(proceduralValue("marschner-lobb", {-x, y, z}) == v);
        CHECK(proceduralValue("marschner-lobb", {x, -y, z}) == v);
        CHECK(proceduralValue("marschner-lobb", {y, x, z}) == v);
      }
  // The grid samples keep the symmetry up to rounding of node positions.
  const Brick b = openProcedural("marschner-lobb", {41, 41, 41})->readAll();
  for (std::int64_t i = 0; i < 41; i += 3)
    for (std::int64_t j = 0; j < 41; j += 5)
      for (std::int64_t k = 0; k < 41; k += 7) {
        CHECK(b.valueAt({40 - i, j, k}) == Approx(b.valueAt({i, j, k})).margin(1e-6));
        CHECK(b.valueAt({j, i, k}) == Approx(b.valueAt({i, j, k})).margin(1e-6));
      }
}

TEST_CASE("Shepp-Logan has skull, brain and ventricles where Kak & Slaney put them", "[io]") {
  CHECK(proceduralValue("shepp-logan", {0, 0, 0}) == Approx(0.2));         // brain
  CHECK(proceduralValue("shepp-logan", {0, 0.9, 0}) == Approx(1.0));       // skull
  CHECK(proceduralValue("shepp-logan", {0, 0, 0.95}) == 0.0);              // outside the head
  CHECK(proceduralValue("shepp-logan", {-0.22, 0, -0.25}) == Approx(0.0)); // ventricles
  CHECK(proceduralValue("shepp-logan", {0.22, 0, -0.25}) == Approx(0.0));
  CHECK(proceduralValue("shepp-logan", {0.06, -0.105, 0.625}) == Approx(0.4));
  // Above the inner features (z = 0.35) only skull and brain remain: mirror symmetric.
  for (double x = -0.95; x <= 0.95; x += 0.1)
    for (double y = -0.95; y <= 0.95; y += 0.1) {
      const double v = proceduralValue("shepp-logan", {x, y, 0.35});
      CHECK(proceduralValue("shepp-logan", {-x, y, 0.35}) == v);
      CHECK(proceduralValue("shepp-logan", {x, -y, 0.35}) == v);
    }
}

TEST_CASE("a procedural sub-box equals the same box cut from the whole volume", "[io]") {
  const NodeBox owned{{3, 2, 4}, {10, 9, 8}};
  const NodeBox stored = owned.grown(2);
  for (const std::string& name : proceduralNames()) {
    INFO(name);
    const auto src = openProcedural(name, {17, 13, 11});
    const Brick whole = src->readAll();
    const Brick part = src->readBox(owned, stored);
    REQUIRE(part.stored() == stored);
    for (std::int64_t z = stored.lo.z; z <= stored.hi.z; ++z)
      for (std::int64_t y = stored.lo.y; y <= stored.hi.y; ++y)
        for (std::int64_t x = stored.lo.x; x <= stored.hi.x; ++x)
          REQUIRE(part.valueAt({x, y, z}) == whole.valueAt({x, y, z}));
    // And each node is the analytic field at its position, in float32.
    const IVec3 n{5, 6, 7};
    CHECK(part.valueAt(n) == double(float(proceduralValue(name, src->grid().nodePosition(n)))));
  }
}

TEST_CASE("procedural volumes refuse unknown names and bad grids", "[io]") {
  REQUIRE_THROWS_WITH(openProcedural("teapot", {8, 8, 8}),
                      Catch::StartsWith("teapot") && Contains("unknown procedural volume") && Contains("shepp-logan"));
  REQUIRE_THROWS_WITH(proceduralValue("teapot", {0, 0, 0}), Contains("unknown procedural volume"));
  REQUIRE_THROWS_WITH(openProcedural("shepp-logan", {8, 0, 8}), Contains("dimension 1 is 0"));
  REQUIRE_THROWS_WITH(openProcedural("shepp-logan", {8, 8, 8}, Vec3{1, -1, 1}), Contains("spacing 1"));
  const auto src = openProcedural("shepp-logan", {8, 8, 8});
  const NodeBox outside{{0, 0, 0}, {8, 7, 7}};
  REQUIRE_THROWS_WITH(src->readBox(outside, outside), Catch::StartsWith("shepp-logan") && Contains("lie in the grid"));
}
