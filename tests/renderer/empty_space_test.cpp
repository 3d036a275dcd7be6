// Empty-space skipping's traversal (renderer/raycast/cast_ray.h): rays
// start and end their walk at the box of visible macrocells
// (MacrocellGrid::visibleFirst(), kernel::clipToVisible) and cross the
// empty cube the distance field proves around a macrocell in one step
// (kernel::emptyExit). Neither may change the image beyond rounding: a
// ray's samples in invisible macrocells add nothing, and both only decide
// which of them the ray walks past.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "raycast/cast_ray.h"
#include "raycast/cast_ray_levels.h"
#include "raycast/kernel.h"
#include "raycast/kernel_setup.h"
#include "raycast/leap_distance.h"
#include "raycast/macrocells.h"
#include "raycast/raycaster.h"
#include "raycast/step_levels.h"
#include "raycast/tile_start.h"
#include "reference.h"
#include "transfer.h"

namespace pvr::core {
namespace {



// uint8 values: 0 around, a soft blob of up to 120 in the middle of the
// 40^3 grid and a speck of 250 at the eight nodes of cell (37, 1, 37), in
// a corner.
Brick speckVolume() {
  const GridGeometry grid = cubeGrid(40);
  return makeVolume(grid, ScalarType::kUInt8, [](Vec3 p) {
    const Vec3 blob = p - Vec3{20, 19, 21}, speck = p - Vec3{37.5, 1.5, 37.5};
    if (std::max({std::abs(speck.x), std::abs(speck.y), std::abs(speck.z)}) < 0.6) return 250.0;
    return 120.0 * std::exp(-dot(blob, blob) / (2 * 5.0 * 5.0));
  });
}

// Opacity only above 200: the speck alone is visible.
TransferFunctionSpec speckOnly() { return transfer({{0, 0, 0, 0, 0}, {200, 1, 0.5, 0.2, 0}, {250, 1, 0.5, 0.2, 0.9}}); }

// Opacity from 40 up: the blob and the speck.
TransferFunctionSpec blobAndSpeck() {
  return transfer({{0, 0, 0, 0, 0}, {40, 0.2, 0.5, 0.9, 0}, {120, 0.4, 0.8, 0.6, 0.3}, {250, 1, 0.5, 0.2, 0.9}});
}

Image render(const BrickRenderer& r, const Camera& camera, const RenderOptions& o, RenderStats* stats = nullptr) {
  return r.render(camera, o, pool(), stats).toFullFrame();
}

double coverage(const Image& image) {
  double sum = 0;
  for (const Rgba& p : image.pixels()) sum += p.a;
  return sum;
}

// Views of the speck's corner: from outside, grazing the face it is next
// to, and from inside the volume.
std::vector<Camera> cornerViews() {
  return {makeCamera(Projection::kPerspective, {80, -40, 75}, {20, 20, 20}, {0, 0, 1}, 45, 64, 64),
          makeCamera(Projection::kOrthographic, {20, -60, 38}, {20, 20, 38}, {0, 0, 1}, 60, 64, 64),
          makeCamera(Projection::kPerspective, {10, 30, 12}, {37, 2, 37}, {0, 0, 1}, 70, 64, 64)};
}

// The least box of the macrocells whose nodes hold a value the table
// shows, by brute force: global macrocell indices, lo > hi when none.
std::pair<IVec3, IVec3> visibleBoxOf(const Brick& volume, const TransferTable& table) {
  constexpr int kSize = MacrocellGrid::kSize;
  const IVec3 dims = volume.grid().dims;
  const auto* v = reinterpret_cast<const std::uint8_t*>(volume.bytes());
  IVec3 lo{1 << 20, 1 << 20, 1 << 20}, hi{-1, -1, -1};
  for (std::int64_t mz = 0; mz * kSize < dims.z - 1; ++mz)
    for (std::int64_t my = 0; my * kSize < dims.y - 1; ++my)
      for (std::int64_t mx = 0; mx * kSize < dims.x - 1; ++mx) {
        int least = 255, most = 0;
        for (std::int64_t z = mz * kSize; z <= std::min(dims.z - 1, (mz + 1) * kSize); ++z)
          for (std::int64_t y = my * kSize; y <= std::min(dims.y - 1, (my + 1) * kSize); ++y)
            for (std::int64_t x = mx * kSize; x <= std::min(dims.x - 1, (mx + 1) * kSize); ++x) {
              const int value = v[(z * dims.y + y) * dims.x + x];
              least = std::min(least, value);
              most = std::max(most, value);
            }
        if (!table.anyVisible(least, most)) continue;
        const IVec3 m{mx, my, mz};
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::min(lo[a], m[a]);
          hi[a] = std::max(hi[a], m[a]);
        }
      }
  return {lo, hi};
}

// A blob in one corner of a 96^3 grid and a speck in the opposite one:
// the visible box is the whole grid and the blob lies between empty space.
Brick blobAndSpeckVolume() {
  return makeVolume(cubeGrid(96), ScalarType::kUInt8, [](Vec3 p) {
    const Vec3 blob = p - Vec3{70, 66, 72}, speck = p - Vec3{6.5, 8.5, 5.5};
    if (std::max({std::abs(speck.x), std::abs(speck.y), std::abs(speck.z)}) < 0.6) return 250.0;
    return 120.0 * std::exp(-dot(blob, blob) / (2 * 5.0 * 5.0));
  });
}

// The rays of the 16x16 tile at (tx, ty), sample k at k * step.
std::vector<RaySetup> tileRays(const Camera& camera, int tx, int ty, const GridGeometry& grid, double step) {
  std::vector<RaySetup> rays;
  for (int y = ty; y < ty + 16; ++y)
    for (int x = tx; x < tx + 16; ++x) rays.push_back(raySetup(camera.ray(x, y), grid, step, Vec3{0, 0, 1}));
  return rays;
}

}  // namespace

// The box is the least one holding every visible macrocell (global
// indices), follows each classify() of the same grid (narrow, widened,
// empty) and holds every macrocell with skipping off.
TEST_CASE("the visible box holds the visible macrocells of the transfer function in use", "[raycast]") {
  const Brick volume = speckVolume();
  MacrocellGrid grid(volume);
  REQUIRE(grid.count() == IVec3{10, 10, 10});  // 39 cells a side

  // The speck alone: nodes 37..38, 1..2, 37..38 lie in macrocell (9, 0, 9) only.
  const TransferTable speck(speckOnly(), 0.5);
  grid.classify(speck, true);
  CHECK(grid.visibleFirst() == IVec3{9, 0, 9});
  CHECK(grid.visibleLast() == IVec3{9, 0, 9});
  CHECK(visibleBoxOf(volume, speck) == std::pair{IVec3{9, 0, 9}, IVec3{9, 0, 9}});

  // Widened by the next transfer function: the blob's macrocells join.
  const TransferTable both(blobAndSpeck(), 0.5);
  grid.classify(both, true);
  const auto [lo, hi] = visibleBoxOf(volume, both);
  CHECK(grid.visibleFirst() == lo);
  CHECK(grid.visibleLast() == hi);
  CHECK(lo.x < 9);
  CHECK(hi.y > 0);

  grid.classify(TransferTable(transfer({{0, 1, 1, 1, 0}, {255, 1, 1, 1, 0}}), 0.5), true);
  for (int a = 0; a < 3; ++a) CHECK(grid.visibleFirst()[a] > grid.visibleLast()[a]);

  grid.classify(speck, false);
  CHECK(grid.visibleFirst() == IVec3{0, 0, 0});
  CHECK(grid.visibleLast() == IVec3{9, 9, 9});
}

// Identity: skipping on equals skipping off up to rounding (1e-6), for a
// speck alone in the corner (the box one macrocell wide: almost every ray
// misses it and costs nothing) and after a transfer-function change
// widens the box on the same renderer. Both scenes must show something:
// a box that left the speck out would leave its pixels black.
TEST_CASE("a speck in a corner of the volume is still hit after clipping to the visible box", "[raycast]") {
  const Brick volume = speckVolume();
  for (const Camera& camera : cornerViews()) {
    for (bool pre : {false, true}) {
      for (double step : {0.5, 0.9}) {
        INFO((pre ? "preintegrated" : "plain") << " step " << step);
        RenderOptions o = makeOptions(step, pre);
        BrickRenderer skipping(volume);
        skipping.classify(speckOnly(), o);
        RenderStats few;
        const Image speck = render(skipping, camera, o, &few);

        RenderOptions full = o;
        full.skipEmpty = false;
        BrickRenderer walking(volume);
        walking.classify(speckOnly(), full);
        RenderStats all;
        const Image speckFull = render(walking, camera, full, &all);
        REQUIRE(coverage(speckFull) > 0.1);
        CHECK(compareImages(speck, speckFull).maxAbs <= 1e-6);
        CHECK(few.samples * 20 < all.samples);

        // The same renderer, classified again for a transfer function
        // that shows the blob as well.
        skipping.classify(blobAndSpeck(), o);
        walking.classify(blobAndSpeck(), full);
        const Image both = render(skipping, camera, o);
        const Image bothFull = render(walking, camera, full);
        REQUIRE(coverage(bothFull) > coverage(speckFull) + 1);
        CHECK(compareImages(both, bothFull).maxAbs <= 1e-6);
      }
    }
  }
}

// emptyExit: every sample before the exit lies in the cube of macrocells
// within distance - 1 of m (the samples it skips), the exit is at least
// k + 1, and it leaps at least distance - 1 macrocells along the ray's
// major axis (what the distance field allowed before). Rays in every
// octant, axis-parallel and oblique, from anywhere in m.
TEST_CASE("a ray crosses the empty cube around its macrocell in one leap", "[raycast]") {
  constexpr int kShift = MacrocellGrid::kShift, kSize = MacrocellGrid::kSize;
  std::uint32_t seed = 12345;
  auto uniform = [&] {
    seed = seed * 1664525u + 1013904223u;
    return double(seed >> 8) / double(1u << 24);
  };
  for (int trial = 0; trial < 2000; ++trial) {
    Vec3 dir{uniform() - 0.5, uniform() - 0.5, uniform() - 0.5};
    if (trial % 7 == 0) dir = Vec3{0, 0, 0}, dir[trial % 3] = trial % 2 ? 1.0 : -1.0;
    dir = normalize(dir);
    const double step = 0.25 + 2 * uniform();
    const int m[3] = {10 + int(uniform() * 20), 10 + int(uniform() * 20), 10 + int(uniform() * 20)};
    const int distance = 1 + int(uniform() * 8);
    RaySetup r{};
    double major = 0;
    const std::int64_t k = std::int64_t(uniform() * 50);
    for (int a = 0; a < 3; ++a) {
      r.step[a] = dir[a] * step;
      r.invStep[a] = r.step[a] != 0 ? 1 / r.step[a] : 0;
      // Sample k somewhere in macrocell m.
      r.origin[a] = double(m[a] * kSize) + uniform() * kSize - double(k) * r.step[a];
      major = std::max(major, std::abs(r.step[a]));
    }
    const std::int64_t exit = kernel::emptyExit(r, m, distance, k, kShift);
    INFO("trial " << trial << " distance " << distance << " k " << k << " exit " << exit);
    REQUIRE(exit >= k + 1);
    CHECK(double(exit - k) >= std::floor(double(distance - 1) * kSize / major) - 1e-9);
    for (std::int64_t s = k; s < exit; ++s)
      for (int a = 0; a < 3; ++a) {
        const double u = r.origin[a] + double(s) * r.step[a];
        CHECK(u >= double((m[a] - distance + 1) * kSize) - 1e-9);
        CHECK(u <= double((m[a] + distance) * kSize) + 1e-9);
      }
  }
}

// pastEmpty by a direction octant's forward field (leap_distance.h,
// forwardLeapDistance): over random visibility grids and random rays from
// anywhere in the grid, every sample a leap passes lies in an empty
// macrocell, judged by the sample's own float position as the kernel
// computes it. A field one macrocell too long anywhere, or one reaching
// backwards, lets some leap pass a visible macrocell here. The forward
// leaps also take fewer look-ups than the cube's over the same rays.
TEST_CASE("a ray leaps by its octant's forward field only across empty macrocells", "[raycast]") {
  constexpr int kShift = MacrocellGrid::kShift, kSize = MacrocellGrid::kSize;
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const IVec3 n{19, 23, 17};
  std::int64_t forwardLookUps = 0, cubeLookUps = 0, passed = 0;
  for (double density : {0.002, 0.01, 0.04, 0.15}) {
    std::vector<std::uint8_t> visible(std::size_t(n.product()));
    std::bernoulli_distribution coin(density);
    for (auto& v : visible) v = coin(rng) ? 0 : 255;
    std::vector<std::uint8_t> cube = visible;
    leapDistance(cube.data(), n);
    std::vector<std::vector<std::uint8_t>> forward(8, visible);
    for (int o = 0; o < 8; ++o) forwardLeapDistance(forward[std::size_t(o)].data(), n, o);
    KernelParams p;
    for (int a = 0; a < 3; ++a) {
      p.mcFirst[a] = 0;
      p.mcCount[a] = n[a];
    }
    for (int trial = 0; trial < 3000; ++trial) {
      Vec3 dir{uniform(rng) - 0.5, uniform(rng) - 0.5, uniform(rng) - 0.5};
      if (trial % 11 == 0) dir[trial % 3] = 0;  // in a plane of the grid
      if (trial % 13 == 0) dir = Vec3{0, 0, 0}, dir[trial % 3] = trial % 2 ? 1.0 : -1.0;
      dir = normalize(dir);
      RaySetup r{};
      const double step = 0.2 + 1.5 * uniform(rng);
      for (int a = 0; a < 3; ++a) {
        r.origin[a] = uniform(rng) * n[a] * kSize;
        r.step[a] = dir[a] * step;
        r.invStep[a] = r.step[a] != 0 ? 1 / r.step[a] : 0;
      }
      const int octant = kernel::octantOf(r);
      const float o[3] = {float(r.origin[0]), float(r.origin[1]), float(r.origin[2])};
      const float d[3] = {float(r.step[0]), float(r.step[1]), float(r.step[2])};
      const kernel::CubeExit exit(r, kShift);
      // The samples' macrocells while the ray is in the grid.
      auto macrocell = [&](std::int64_t s, int* m) {
        bool in = true;
        for (int a = 0; a < 3; ++a) {
          const float u = o[a] + float(s) * d[a];
          in = in && u >= 0 && u < float(n[a] * kSize);
          m[a] = int(u) >> kShift;
        }
        return in;
      };
      auto walk = [&](const std::uint8_t* field, bool check) {
        std::int64_t lookUps = 0;
        int m[3];
        for (std::int64_t k = 0; macrocell(k, m);) {
          const std::int64_t next = kernel::pastEmpty(p, field, exit, o, d, k, kShift);
          ++lookUps;
          if (next == k) {
            ++k;
            continue;
          }
          for (std::int64_t s = k; check && s < next && macrocell(s, m); ++s) {
            ++passed;
            if (visible[std::size_t((m[2] * n.y + m[1]) * n.x + m[0])] == 0)
              FAIL("trial " << trial << " octant " << octant << ": the leap from sample " << k << " to " << next
                            << " passes sample " << s << " in visible macrocell " << m[0] << " " << m[1] << " "
                            << m[2]);
          }
          k = next;
        }
        return lookUps;
      };
      forwardLookUps += walk(forward[std::size_t(octant)].data(), true);
      cubeLookUps += walk(cube.data(), false);
    }
  }
  INFO("look-ups: forward " << forwardLookUps << ", cube " << cubeLookUps << "; samples passed " << passed);
  CHECK(passed > 100000);
  CHECK(forwardLookUps < cubeLookUps);
}

// frameOctants holds the octant of every camera ray through the
// rectangle and no other, and leapFields gives the first of them their
// forward fields, as many as the budget keeps (one for this uint8 brick),
// and the cube's field to the others.
TEST_CASE("a frame leaps by the forward fields of its rays' octants", "[raycast]") {
  const Brick volume = speckVolume();
  BrickRenderer renderer(volume);
  renderer.classify(blobAndSpeck(), makeOptions(0.5, false));
  const MacrocellGrid& grid = renderer.macrocells();
  REQUIRE(grid.forwardFieldsKept() == 1);
  const std::vector<Camera> cameras = {
      makeCamera(Projection::kPerspective, {80, -40, 75}, {20, 20, 20}, {0, 0, 1}, 20, 32, 32),    // one octant
      makeCamera(Projection::kPerspective, {20, 20, -80}, {20, 20, 20}, {0, 1, 0}, 40, 32, 32),    // four
      makeCamera(Projection::kPerspective, {20, 19, 21}, {30, 25, 25}, {0, 0, 1}, 120, 32, 32),    // inside: five
      makeCamera(Projection::kOrthographic, {20, -60, 20}, {20, 20, 20}, {0, 0, 1}, 40, 32, 32)};  // one
  const std::size_t want[] = {1, 4, 5, 1};
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    CAPTURE(c);
    const std::vector<int> octants = frameOctants(cameras[c], PixelRect{0, 0, 32, 32});
    CHECK(octants.size() == want[c]);
    int rays[8] = {};
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x)
        ++rays[kernel::octantOf(raySetup(cameras[c].ray(x, y), volume.grid(), 0.5, Vec3{0, 0, 1}))];
    for (int o = 0; o < 8; ++o) CHECK((rays[o] > 0) == (std::find(octants.begin(), octants.end(), o) != octants.end()));
    const MacrocellGrid::LeapFields fields = grid.leapFields(octants, &pool());
    for (int o = 0; o < 8; ++o) {
      const bool own = fields.byOctant[o] != grid.distance();
      CHECK(own == (o == octants.front()));
      if (!own) continue;
      std::vector<std::uint8_t> exact(grid.distance(), grid.distance() + grid.count().product());
      forwardLeapDistance(exact.data(), grid.count(), o);
      CHECK(std::equal(exact.begin(), exact.end(), fields.byOctant[o]));
    }
  }
}

// castRays takes up to kRaysAtOnce rays' walks by turns (with AVX-512,
// their look-ups in vector lanes, walk_lanes.h): each ray's result must be
// exactly castRay's for it (colour, samples, hit), whatever its neighbours
// do: rays that miss the brick, miss the visible box, cross the speck, the
// blob, or stop early at the early-termination opacity, in runs of every
// length; plain, pre-integrated and shaded; from the eight corners (every
// octant, each leaping by its own forward field) and from inside.
TEST_CASE("rays cast by turns equal rays cast one at a time", "[raycast]") {
  const Brick volume = speckVolume();
  const TransferFunctionSpec tf = blobAndSpeck();
  std::vector<Camera> cameras = {
      makeCamera(Projection::kPerspective, {70, -35, 60}, {22, 18, 24}, {0, 0, 1}, 22, 40, 40),
      makeCamera(Projection::kPerspective, {21, 18, 20}, {30, 26, 25}, {0, 0, 1}, 110, 24, 24)};
  for (int corner = 0; corner < 8; ++corner)
    cameras.push_back(makeCamera(Projection::kPerspective,
                                 {corner & 1 ? 75.0 : -35.0, corner & 2 ? 72.0 : -32.0, corner & 4 ? 70.0 : -30.0},
                                 {20, 19, 21}, {0, 0, 1}, 40, 24, 24));
  for (bool pre : {false, true}) {
    for (bool shaded : {false, true}) {
      INFO((pre ? "preintegrated" : "plain") << (shaded ? " shaded" : ""));
      RenderOptions o = makeOptions(0.6, pre, shaded);
      o.earlyTermination = 0.5;
      MacrocellGrid macrocells(volume);
      const TransferTable table(tf, o.step);
      const PreintegratedTable preintegrated(tf);
      macrocells.classify(table, true);
      KernelParams p;
      setBrick(p, volume, macrocells);
      setTables(p, table, pre ? &preintegrated : nullptr, o.step);
      const std::vector<float> specular = specularTable(o.shading.shininess);
      setOptions(p, o, specular.data());
      std::vector<std::uint8_t> forward[8];  // every octant's own field
      for (int oct = 0; oct < 8; ++oct) {
        forward[oct].assign(macrocells.distance(), macrocells.distance() + macrocells.count().product());
        forwardLeapDistance(forward[oct].data(), macrocells.count(), oct);
        p.leapField[oct] = forward[oct].data();
      }
      auto one = pre ? (shaded ? &castRay<std::uint8_t, true, true> : &castRay<std::uint8_t, false, true>)
                     : (shaded ? &castRay<std::uint8_t, true, false> : &castRay<std::uint8_t, false, false>);
      auto turns = pre ? (shaded ? &castRays<std::uint8_t, true, true> : &castRays<std::uint8_t, false, true>)
                       : (shaded ? &castRays<std::uint8_t, true, false> : &castRays<std::uint8_t, false, false>);
      int hits = 0, terminated = 0, octants = 0, rayCount = 0;
      for (const Camera& camera : cameras) {
        const Vec3 light = normalize(camera.toWorld(o.shading.lightDirection));
        for (int y = 0; y < camera.height(); ++y) {
          for (int x = 0, n = 1; x < camera.width(); x += n, n = n % kRaysAtOnce + 1) {
            const int count = std::min(n, camera.width() - x);
            RaySetup rays[kRaysAtOnce];
            for (int i = 0; i < count; ++i) rays[i] = raySetup(camera.ray(x + i, y), volume.grid(), o.step, light);
            RayResult together[kRaysAtOnce];
            turns(p, rays, count, MacrocellGrid::kShift, kernel::TileSpan{}, together);
            for (int i = 0; i < count; ++i) {
              const RayResult alone = one(p, rays[i], MacrocellGrid::kShift, kernel::TileSpan{});
              INFO("pixel " << x + i << ", " << y);
              CHECK(together[i].hit == alone.hit);
              CHECK(together[i].samples == alone.samples);
              CHECK(together[i].colour.r == alone.colour.r);
              CHECK(together[i].colour.g == alone.colour.g);
              CHECK(together[i].colour.b == alone.colour.b);
              CHECK(together[i].colour.a == alone.colour.a);
              hits += alone.samples > 0;
              terminated += alone.colour.a >= 0.5f;
              octants |= 1 << kernel::octantOf(rays[i]);
              ++rayCount;
            }
          }
        }
      }
      // The views must hold every kind of ray for the check to mean anything.
      CHECK(hits > 1000);
      CHECK(hits < rayCount - 1000);
      CHECK(terminated > 100);
      CHECK(octants == 0xff);
    }
  }
}


// tileSpan (tile_start.h) finds once per tile where its rays can first
// and last meet a visible macrocell, and each ray walks only between:
// no sample of any of the tile's rays before or after that span may lie
// in a visible macrocell (each sample's macrocell as the walk finds it,
// from its float position). A blob in one corner of a 96^3 grid and a
// speck in the opposite one, so that the visible box is the whole grid
// and the blob lies between empty space; views from outside (perspective
// and orthographic), from inside the volume, and tiles that straddle the
// silhouette. The marches must also cross at least half of the empty
// space in front of and behind what most tiles meet, or they prove
// nothing.
TEST_CASE("a tile's rays walk only where one of them can meet a visible macrocell", "[raycast]") {
  const Brick volume = blobAndSpeckVolume();
  const std::vector<Camera> views = {
      makeCamera(Projection::kPerspective, {-120, -100, -80}, {70, 66, 72}, {0, 0, 1}, 12, 64, 64),
      makeCamera(Projection::kOrthographic, {-60, 66, 72}, {70, 66, 72}, {0, 0, 1}, 40, 64, 64),
      makeCamera(Projection::kOrthographic, {6, -80, 6}, {6, 8, 6}, {0, 0, 1}, 30, 64, 64),
      makeCamera(Projection::kPerspective, {20, 15, 25}, {70, 66, 72}, {0, 0, 1}, 40, 64, 64),
      makeCamera(Projection::kPerspective, {250, 66, 72}, {70, 66, 72}, {0, 0, 1}, 8, 64, 64),
      makeCamera(Projection::kPerspective, {250, 150, 170}, {6, 8, 6}, {0, 0, 1}, 6, 64, 64)};
  constexpr int kShift = MacrocellGrid::kShift;
  constexpr std::int64_t kNone = std::numeric_limits<std::int64_t>::max();
  // The speck alone: the visible box is one macrocell, where the rays
  // start and end already; only the marches' soundness is tested.
  for (const bool speckAlone : {false, true}) {
    const TransferFunctionSpec tf = speckAlone ? speckOnly() : blobAndSpeck();
    for (double step : {0.3, 1.0, 2.5}) {
      MacrocellGrid macrocells(volume);
      const TransferTable table(tf, step);
      macrocells.classify(table, true);
      KernelParams p;
      setBrick(p, volume, macrocells);
      setTables(p, table, nullptr, step);
      auto visibleAt = [&](const RaySetup& r, std::int64_t k) {
        int m[3];
        for (int a = 0; a < 3; ++a) {
          const float u = std::fma(float(k), float(r.step[a]), float(r.origin[a]));
          m[a] = std::clamp(int(u) >> kShift, p.mcFirst[a], p.mcFirst[a] + p.mcCount[a] - 1);
        }
        return p.distance[kernel::macrocellIndex(p, m)] == 0;
      };
      int frontTiles = 0, frontCrossed = 0, backTiles = 0, backCrossed = 0;
      for (std::size_t v = 0; v < views.size(); ++v) {
        const Camera& camera = views[v];
        for (int ty = 0; ty < camera.height(); ty += 16)
          for (int tx = 0; tx < camera.width(); tx += 16) {
            const std::vector<RaySetup> rays = tileRays(camera, tx, ty, volume.grid(), step);
            const kernel::TileSpan span = kernel::tileSpan(p, rays.data(), int(rays.size()), kShift);
            INFO("view " << v << " step " << step << " tile " << tx << ", " << ty << " span " << span.from << " "
                         << span.to);
            // The samples of all rays in the visible box, [earliest,
            // latest]: where they would walk without the marches; and
            // the first and last in a visible macrocell.
            std::int64_t earliest = kNone, latest = -1, firstVisible = kNone, lastVisible = -1;
            for (const RaySetup& r : rays) {
              std::int64_t first, last;
              if (!kernel::sampleRange(p, r, first, last)) continue;
              std::int64_t k = first, end = last;
              if (kernel::clipToVisible(p, r, k, end)) {
                earliest = std::min(earliest, k);
                latest = std::max(latest, end);
              }
              for (std::int64_t s = first; s <= last; ++s)
                if (visibleAt(r, s)) {
                  firstVisible = std::min(firstVisible, s);
                  lastVisible = std::max(lastVisible, s);
                }
            }
            REQUIRE(span.from <= firstVisible);
            REQUIRE(span.to >= lastVisible);
            if (firstVisible == kNone) continue;
            // Where the rays cross empty space in the visible box before
            // (after) they meet anything, the march should cross at least
            // half of it.
            if (double(firstVisible - earliest) * step > 4.0 * MacrocellGrid::kSize) {
              ++frontTiles;
              frontCrossed += 2 * (span.from - earliest) >= firstVisible - earliest;
            }
            if (double(latest - lastVisible) * step > 4.0 * MacrocellGrid::kSize) {
              ++backTiles;
              backCrossed += 2 * (latest - span.to) >= latest - lastVisible;
            }
          }
      }
      INFO("step " << step << ": " << frontCrossed << " of " << frontTiles << " tiles crossed the front, "
                   << backCrossed << " of " << backTiles << " the back");
      if (!speckAlone) {
        CHECK(frontTiles >= 5);
        CHECK(frontCrossed * 4 >= frontTiles * 3);
        CHECK(backTiles >= 5);
        CHECK(backCrossed * 4 >= backTiles * 3);
      }
    }
  }
}

// Quality chosen by error (castRayByLevels) walks only the tile's span as
// castRay does: the same colours as without the span to the last bit; and
// a span cut short ends the rays there (the span is used, not just
// computed). castRaysByLevels, sixteen rays started and walked at once,
// draws each ray as castRayByLevels does, to the last bit and sample.
// The blob between empty space, seen so that the rays cross empty space
// before and behind it; shaded and not, at a target that mixes levels.
TEST_CASE("the step chosen per region walks only the tile's span and draws the same rays, one at a time or sixteen at once", "[raycast][levels]") {
  const Brick volume = blobAndSpeckVolume();
  const std::vector<Camera> views = {
      makeCamera(Projection::kPerspective, {-120, -100, -80}, {70, 66, 72}, {0, 0, 1}, 12, 48, 48),
      makeCamera(Projection::kOrthographic, {-60, 66, 72}, {70, 66, 72}, {0, 0, 1}, 40, 48, 48)};
  constexpr int kShift = MacrocellGrid::kShift;
  const TransferFunctionSpec tf = blobAndSpeck();
  const double sceneStep = 1.0, fine = fineStep(sceneStep);
  StepLevels levels(volume, sceneStep);
  levels.choose(tf, 40.0, 0.0);
  std::vector<TransferTable> tables;
  for (int l = 0; l < kStepLevels; ++l) tables.emplace_back(tf, fine * double(1 << l));
  MacrocellGrid macrocells(volume);
  macrocells.classify(tables.front(), true);
  KernelParams p;
  setBrick(p, volume, macrocells);
  setTables(p, tables.front(), nullptr, fine);
  std::vector<KernelParams> atLevel;
  setLevels(p, levels, tables, fine, atLevel);
  for (const bool shaded : {false, true}) {
    RenderOptions o = makeOptions(sceneStep, false, shaded);
    const std::vector<float> specular = specularTable(o.shading.shininess);
    setOptions(p, o, specular.data());
    for (KernelParams& q : atLevel) setOptions(q, o, specular.data());
    auto cast = shaded ? &castRayByLevels<std::uint8_t, true> : &castRayByLevels<std::uint8_t, false>;
    std::uint64_t samplesWithSpan = 0, samplesCut = 0;
    int hits = 0;
    for (std::size_t v = 0; v < views.size(); ++v) {
      const Camera& camera = views[v];
      for (int ty = 0; ty < camera.height(); ty += 16)
        for (int tx = 0; tx < camera.width(); tx += 16) {
          const std::vector<RaySetup> rays = tileRays(camera, tx, ty, volume.grid(), fine);
          const kernel::TileSpan span = kernel::tileSpan(p, rays.data(), int(rays.size()), kShift);
          // The tile's rows as the renderer takes them: kRaysAtOnce rays at
          // once (in vector lanes where the CPU has AVX-512).
          std::vector<RayResult> atOnce(rays.size());
          for (std::size_t i = 0; i < rays.size(); i += kRaysAtOnce) {
            const int n = int(std::min<std::size_t>(kRaysAtOnce, rays.size() - i));
            (shaded ? &castRaysByLevels<std::uint8_t, true> : &castRaysByLevels<std::uint8_t, false>)(
                p, &rays[i], n, kShift, span, &atOnce[i]);
          }
          for (std::size_t i = 0; i < rays.size(); ++i) {
            const RayResult with = cast(p, rays[i], kShift, span), without = cast(p, rays[i], kShift, {});
            CHECK(atOnce[i].colour.r == with.colour.r);
            CHECK(atOnce[i].colour.g == with.colour.g);
            CHECK(atOnce[i].colour.b == with.colour.b);
            CHECK(atOnce[i].colour.a == with.colour.a);
            CHECK(atOnce[i].samples == with.samples);
            CHECK(atOnce[i].hit == with.hit);
            const RayResult cut = cast(p, rays[i], kShift, {span.from, span.from + (span.to - span.from) / 4});
            INFO("shaded " << shaded << " view " << v << " tile " << tx << ", " << ty << " ray " << i);
            CHECK(with.colour.r == without.colour.r);
            CHECK(with.colour.g == without.colour.g);
            CHECK(with.colour.b == without.colour.b);
            CHECK(with.colour.a == without.colour.a);
            CHECK(cut.samples <= with.samples);
            samplesWithSpan += with.samples;
            samplesCut += cut.samples;
            hits += without.colour.a > 0.01f;
          }
        }
    }
    INFO("shaded " << shaded << ": " << samplesWithSpan << " samples with the span, " << samplesCut
                   << " with a quarter of it, " << hits << " rays see something");
    CHECK(hits > 50);
    CHECK(2 * samplesCut < samplesWithSpan);
  }
}

}  // namespace pvr::core
