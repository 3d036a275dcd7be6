// castRays' empty-space look-ups in vector lanes (renderer/raycast/
// walk_lanes.h): each lane must land exactly where its ray's scalar
// look-up (kernel::pastEmpty, CubeExit::exit) lands, so that every ray
// takes the same leaps and chunks as castRay and gives the same bits.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "raycast/cast_ray.h"
#include "raycast/macrocells.h"
#include "index_ray.h"

#ifdef PVR_HAVE_WALK_LANES

namespace pvr::core {
namespace {

// Eight rays' look-ups at samples k[i], in lanes and one at a time.
struct EightLook {
  RaySetup rays[kernel::kWalkLanes];
  alignas(64) std::int64_t k[kernel::kWalkLanes];
  kernel::CubeExit cubes[kernel::kWalkLanes];
  float o[kernel::kWalkLanes][3], d[kernel::kWalkLanes][3];
  alignas(64) std::int64_t lanes[kernel::kWalkLanes];  // where WalkLanes::next goes on

  // Lane i leaps through the field of its ray's octant, as RayWalk does.
  void lookUp(const KernelParams& p, int shift) {
    kernel::WalkLanes walk(p, shift);
    for (int i = 0; i < kernel::kWalkLanes; ++i) {
      cubes[i] = kernel::CubeExit(rays[i], shift);
      for (int a = 0; a < 3; ++a) {
        o[i][a] = float(rays[i].origin[a]);
        d[i][a] = float(rays[i].step[a]);
      }
      walk.set(i, o[i], d[i], cubes[i], p.leapField[kernel::octantOf(rays[i])], k[i], k[i] + 100);
    }
    _mm512_store_si512(lanes, walk.next(_mm512_load_si512(k)));
  }
  std::int64_t scalar(const KernelParams& p, int i, int shift) const {
    return kernel::pastEmpty(p, p.leapField[kernel::octantOf(rays[i])], cubes[i], o[i], d[i], k[i], shift);
  }
};

}  // namespace

// Eight rays at a time in random directions (every octant, and steps of 0
// along some axes), each leaping through the field of its own octant,
// looked up from random samples in and around a brick whose macrocells do
// not start at 0 (offset index, clamping at every face), and positions a
// rounding away from a macrocell face: each lane of WalkLanes::next
// equals pastEmpty for its ray, visible or leaping. (Rays walked in lanes
// against rays walked alone: empty_space_test.cpp, "rays cast by turns".)
TEST_CASE("look-ups in vector lanes land where each ray's scalar look-up does", "[raycast]") {
  std::mt19937 rng(13);
  KernelParams p;
  const int first[3] = {3, 5, 2}, count[3] = {7, 9, 6};
  for (int a = 0; a < 3; ++a) {
    p.mcFirst[a] = first[a];
    p.mcCount[a] = count[a];
  }
  const int shift = MacrocellGrid::kShift, size = 1 << shift;
  // A field per octant: distances 0 (visible) to 9, a third of them 0.
  std::vector<std::uint8_t> fields[8];
  std::uniform_int_distribution<int> distance(-4, 9);
  for (int o = 0; o < 8; ++o) {
    fields[o].resize(std::size_t(count[0]) * count[1] * count[2]);
    for (auto& d : fields[o]) d = std::uint8_t(std::max(0, distance(rng)));
    p.leapField[o] = fields[o].data();
  }
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> zeroAxis(0, 5);  // an axis the ray does not move along, now and then
  std::uniform_int_distribution<std::int64_t> sample(0, 400);
  int visible = 0, leaps = 0, farLeaps = 0, clamped = 0, octantsMixed = 0;
  for (int round = 0; round < 4000; ++round) {
    EightLook look;
    int octants = 0;
    for (int i = 0; i < kernel::kWalkLanes; ++i) {
      double origin[3], step[3];
      const int still = zeroAxis(rng);
      for (int a = 0; a < 3; ++a) {
        // Origins around the brick's box (index units), steps up to 1.5 voxels.
        origin[a] = (first[a] + 0.5 * count[a] + 0.8 * count[a] * unit(rng)) * size;
        step[a] = a == still ? 0.0 : 1.5 * unit(rng);
      }
      look.rays[i] = rayOf(origin, step);
      look.k[i] = sample(rng);
      octants |= 1 << kernel::octantOf(look.rays[i]);
    }
    look.lookUp(p, shift);
    octantsMixed += __builtin_popcount(unsigned(octants)) > 1;
    for (int i = 0; i < kernel::kWalkLanes; ++i) {
      const std::int64_t scalar = look.scalar(p, i, shift), k = look.k[i];
      INFO("round " << round << ", lane " << i << ", sample " << k);
      REQUIRE(look.lanes[i] == scalar);
      visible += scalar == k;
      leaps += scalar != k;
      farLeaps += scalar > k + 8;
      for (int a = 0; a < 3; ++a) {
        const int m = int(look.o[i][a] + float(k) * look.d[i][a]) >> shift;
        if (m < first[a] || m >= first[a] + count[a]) {
          ++clamped;
          break;
        }
      }
    }
  }
  // Positions a rounding away from a macrocell face along x: o + k d
  // rounded once (an FMA, as kernel::walkMulAdd) and rounded twice
  // (product, then sum) fall in neighbouring macrocells. Lanes that took
  // the product apart would find the other macrocell here.
  std::uniform_int_distribution<int> face(first[0] + 1, first[0] + count[0] - 1);
  std::uniform_real_distribution<float> stepX(0.05f, 1.5f);
  int ties = 0;
  for (int round = 0; round < 50; ++round) {
    EightLook look;
    for (int i = 0; i < kernel::kWalkLanes; ++i) {
      for (;;) {
        const float dx = stepX(rng);
        const std::int64_t k = sample(rng) % 60 + 1;
        const double target = double(face(rng) * size) - double(k) * double(dx);  // exact product
        const float ox = std::nextafter(float(target), unit(rng) < 0 ? -1e9f : 1e9f);
        volatile float product = float(k) * dx;  // rounded on its own
        const float fused = std::fma(float(k), dx, ox), twice = product + ox;
        if ((int(fused) >> shift) == (int(twice) >> shift)) continue;
        const double origin[3] = {ox, (first[1] + 3.3) * size, (first[2] + 2.6) * size};
        const double step[3] = {dx, 0.02, -0.015};  // leaving by an x face
        look.rays[i] = rayOf(origin, step);
        look.k[i] = k;
        break;
      }
    }
    look.lookUp(p, shift);
    for (int i = 0; i < kernel::kWalkLanes; ++i) {
      INFO("near a face: round " << round << ", lane " << i);
      REQUIRE(look.lanes[i] == look.scalar(p, i, shift));
      ++ties;
    }
  }
  CHECK(ties == 400);
  // Every kind of look-up, often.
  CHECK(visible > 2000);
  CHECK(leaps > 10000);
  CHECK(farLeaps > 800);
  CHECK(clamped > 2000);
  CHECK(octantsMixed > 3000);
}

}  // namespace pvr::core

#endif
