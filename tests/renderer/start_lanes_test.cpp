// castRays' ray starts in vector lanes (renderer/raycast/start_lanes.h):
// every lane that does not leave its ray to RayWalk::start must find
// exactly what RayWalk::start finds (the same samples in the brick, walk
// and chord ends; the same hit and the same verdict on the walk), so that
// every ray gives the same bits. (Whole rays cast in lanes against rays
// cast alone: empty_space_test.cpp, "rays cast by turns".)
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <random>

#include "raycast/cast_ray.h"
#include "raycast/macrocells.h"
#include "index_ray.h"

#ifdef PVR_HAVE_WALK_LANES

namespace pvr::core {
namespace {

constexpr int kDims[3] = {41, 34, 27};

// Brick `piece` of a 2 x 2 x 2 split of the grid at node `cut` (piece -1:
// the whole grid), its visible box [visibleLo, visibleHi] (lo > hi:
// nothing visible). Membership only: no voxels, no macrocells.
KernelParams brickOf(int piece, const int cut[3], const double visibleLo[3], const double visibleHi[3]) {
  KernelParams p;
  for (int a = 0; a < 3; ++a) {
    const int last = kDims[a] - 1;
    const bool upper = piece >= 0 && ((piece >> a) & 1);
    p.ownLo[a] = piece < 0 || !upper ? 0.0 : double(cut[a]);
    p.ownHi[a] = piece < 0 || upper ? double(last) : double(cut[a]);
    p.hiClosed[a] = p.ownHi[a] == double(last);
    p.domainMax[a] = float(last);
    p.visibleLo[a] = visibleLo[a];
    p.visibleHi[a] = visibleHi[a];
  }
  static const std::uint8_t field[1] = {0};
  for (auto& f : p.leapField) f = field;
  return p;
}

using Walk = kernel::RayWalk<std::uint8_t, false, false>;

// Counts of what the lanes decided, to show the cases were met.
struct Tally {
  int scalar = 0, missed = 0, hitOnly = 0, walks = 0, checked = 0;
};

// Rays rays[0, n) started in lanes against RayWalk::start, lane by lane.
void checkLanes(const KernelParams& p, const kernel::TileSpan& span, const RaySetup* rays, int n, Tally& tally) {
  kernel::StartsInLanes s;
  kernel::StartLanes(p, span).start(rays, n, s);
  for (int i = 0; i < n; ++i) {
    const RaySetup& ray = rays[i];
    INFO("lane " << i << ": origin " << ray.origin[0] << " " << ray.origin[1] << " " << ray.origin[2] << ", step "
                 << ray.step[0] << " " << ray.step[1] << " " << ray.step[2]);
    if ((s.scalar >> i) & 1) {
      ++tally.scalar;
      continue;
    }
    ++tally.checked;
    const bool hit = (s.hit >> i) & 1, walks = (s.walks >> i) & 1;
    REQUIRE((!walks || hit));
    if (!hit) {
      // No sample here, and no short chord to draw: no hit.
      std::int64_t first, last;
      double kIn, kOut;
      REQUIRE_FALSE(kernel::sampleRange(p, ray, first, last));
      REQUIRE_FALSE(kernel::shortChord(p, ray, kIn, kOut));
      ++tally.missed;
      continue;
    }
    // With samples here RayWalk::start draws nothing: it only sets up.
    Walk walk;
    RayResult out;
    REQUIRE(walk.start(p, ray, MacrocellGrid::kShift, span, out) == walks);
    REQUIRE(out.hit);
    if (!walks) {
      ++tally.hitOnly;
      continue;
    }
    ++tally.walks;
    const kernel::WalkStart scalar = walk.started(), lanes = s.at(i);
    CHECK(lanes.first == scalar.first);
    CHECK(lanes.last == scalar.last);
    CHECK(lanes.k == scalar.k);
    CHECK(lanes.end == scalar.end);
    CHECK(lanes.ends.first == scalar.ends.first);
    CHECK(lanes.ends.last == scalar.ends.last);
    // Bits, not values: the head and tail scale the end samples' segments.
    CHECK(std::signbit(lanes.ends.head) == std::signbit(scalar.ends.head));
    CHECK(lanes.ends.head == scalar.ends.head);
    CHECK(lanes.ends.tail == scalar.ends.tail);
  }
}

}  // namespace

// Eight rays at a time in random directions (every octant, steps of 0
// along some axes), from origins around and inside the grid, in the whole
// grid and in each brick of a 2 x 2 x 2 split (far faces open inside the
// grid, closed at its edge), with visible boxes large, small and empty,
// and tile spans that cut the walks: each lane equals RayWalk::start.
TEST_CASE("rays started in vector lanes start where RayWalk::start starts them", "[raycast]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> still(0, 7);  // an axis the ray does not move along, now and then
  std::uniform_int_distribution<int> pick(0, 3);
  Tally tally;
  for (int round = 0; round < 6000; ++round) {
    const int cut[3] = {17, 9, 20};
    double visibleLo[3], visibleHi[3];
    for (int a = 0; a < 3; ++a) {
      if (pick(rng) == 0) {  // reaching the brick's outer macrocells
        visibleLo[a] = -1e30;
        visibleHi[a] = 1e30;
      } else {
        visibleLo[a] = kDims[a] * (0.3 + 0.3 * unit(rng)) - 6;
        visibleHi[a] = visibleLo[a] + kDims[a] * (0.8 + 0.3 * unit(rng));
      }
    }
    if (round % 8 == 7) {  // nothing visible
      visibleLo[0] = 1;
      visibleHi[0] = 0;
    }
    const int piece = round % 9 - 1;
    const KernelParams p = brickOf(piece, cut, visibleLo, visibleHi);
    kernel::TileSpan span;
    if (pick(rng) == 0) span = {std::int64_t(40 + 30 * unit(rng)), std::int64_t(90 + 60 * unit(rng))};
    const bool inside = pick(rng) == 0;
    RaySetup rays[kernel::kStartLanes];
    const int n = round % 5 == 0 ? 1 + round % kernel::kStartLanes : kernel::kStartLanes;
    for (int i = 0; i < n; ++i) {
      double origin[3], step[3];
      const int zero = still(rng);
      const double length = 0.3 + 1.7 * (0.5 + 0.5 * unit(rng));
      for (int a = 0; a < 3; ++a) {
        origin[a] = inside ? kDims[a] * (0.5 + 0.5 * unit(rng)) : kDims[a] * (0.5 + 1.5 * unit(rng));
        // Towards a point in or near the grid.
        const bool moves = a != zero && !(zero == 4 && a < 2);
        step[a] = moves ? length * (kDims[a] * (0.5 + 0.6 * unit(rng)) - origin[a]) / (2.0 * kDims[0]) : 0.0;
        // Not moving along an axis, on a face of the brick or the grid, or a rounding off it.
        if (!moves && pick(rng) == 0) {
          const double faces[3] = {0.0, double(cut[a]), double(kDims[a] - 1)};
          origin[a] = faces[pick(rng) % 3];
          if (pick(rng) == 0) origin[a] = std::nextafter(origin[a], unit(rng) < 0 ? -1e9 : 1e9);
        }
      }
      rays[i] = rayOf(origin, step);
    }
    checkLanes(p, span, rays, n, tally);
  }
  INFO("scalar " << tally.scalar << ", missed " << tally.missed << ", hit only " << tally.hitOnly << ", walks "
                 << tally.walks);
  CHECK(tally.walks > 4000);
  CHECK(tally.hitOnly > 1000);
  CHECK(tally.missed > 1000);
  // Few rays are left to RayWalk::start: rays that clip a corner of the
  // brick between two samples, short chords this brick draws.
  CHECK(tally.scalar < tally.checked / 25);
}

// Rays whose samples lie one rounding from an owned face (the split's
// cut, open, or the grid's far face, closed): there fma(k, step, origin)
// and origin + k * step rounded twice (product, then sum) fall on either
// side of the face, and the lanes must round as inside() does, once.
// Lanes that took the product apart would find the first or last sample
// one off here.
TEST_CASE("rays started in vector lanes round a sample at a face as the scalar start does", "[raycast]") {
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<std::int64_t> sample(3, 60);
  const int cut[3] = {17, 9, 20};
  const double visibleLo[3] = {-1e30, -1e30, -1e30}, visibleHi[3] = {1e30, 1e30, 1e30};  // all of it
  int ties = 0;
  Tally tally;
  for (int round = 0; round < 200; ++round) {
    // The lower brick along x (its far face the open cut) or the upper
    // (its far face the grid's, closed); rays along +x or -x through it.
    const int piece = round % 2;
    const KernelParams p = brickOf(piece, cut, visibleLo, visibleHi);
    const double face = round % 4 < 2 ? double(cut[0]) : double(kDims[0] - 1);
    RaySetup rays[kernel::kStartLanes];
    for (int i = 0; i < kernel::kStartLanes; ++i) {
      for (;;) {
        const double dx = (round % 3 == 0 ? -1 : 1) * (0.05 + 0.7 * (0.5 + 0.5 * unit(rng)));
        const std::int64_t k = sample(rng);
        const double target = face - double(k) * dx;
        const double ox = std::nextafter(target, unit(rng) < 0 ? -1e9 : 1e9);
        volatile double product = double(k) * dx;  // rounded on its own
        const double fused = std::fma(double(k), dx, ox), twice = product + ox;
        if ((fused < face) == (twice < face) && (fused <= face) == (twice <= face)) continue;
        const double origin[3] = {ox, 4.3 + 0.1 * i, 5.6};
        const double step[3] = {dx, 0.02, 0.015};
        rays[i] = rayOf(origin, step);
        ++ties;
        break;
      }
    }
    checkLanes(p, kernel::TileSpan{}, rays, kernel::kStartLanes, tally);
  }
  CHECK(ties == 200 * kernel::kStartLanes);
  CHECK(tally.walks > 1000);
}

}  // namespace pvr::core

#endif
