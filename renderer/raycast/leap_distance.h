// The distance field that space leaping reads, computed at memory speed.
//
// A ray in an empty macrocell at distance d may leap d - 1 macrocells
// (macrocells.h). The exact chessboard transform (chessboardDistance)
// follows a data-dependent chain per element: over the 16 M macrocells a
// rank holds of a 2048^3 volume it cost more than computing the bounds
// themselves. A leap needs only a distance that never exceeds the true one,
// and is worth most near what is visible, so the field is
//   - exact below kNear, by three separable windowed min-max passes that
//     run across whole rows at once (vectorised, no chains);
//   - beyond, the bound a coarse grid gives: blocks of kBlock^3
//     macrocells, visible when any of theirs is; at a coarse chessboard
//     distance D >= 1 every visible macrocell is at least kBlock (D - 1) + 1
//     away, since D - 1 whole blocks lie between. The coarse grid is
//     kBlock^3 times smaller, so its exact transform costs nothing.
// Rays far from anything visible leap at most kBlock macrocells less than
// the exact field would let them.
#pragma once

#include <cstdint>

#include "../vec.h"

namespace pvr::core {

class ThreadPool;

inline constexpr int kLeapNear = 16;   // exact below this many macrocells
inline constexpr int kLeapBlock = 16;  // coarse block edge, in macrocells
// Within one block every macrocell is nearer than kLeapNear, so a block
// holding something visible never needs the coarse bound.
static_assert(kLeapNear >= kLeapBlock, "a block's own macrocells must be within the exact range");

// Whether `leap` is what leapDistance promises for a macrocell whose exact
// chessboard distance (capped at 255) is `exact`: equal below kLeapNear;
// beyond, at least kLeapNear, never more than the truth, and short of it
// by at most the coarse blocks' slack. For tests and benches.
constexpr bool leapDistanceFits(int leap, int exact) {
  return exact < kLeapNear ? leap == exact
                           : leap >= kLeapNear && leap <= exact && leap >= exact - 2 * (kLeapBlock - 1);
}

// In place over count.x * count.y * count.z bytes (x fastest): on entry 0
// marks a visible macrocell and anything else an empty one; on return each
// holds a distance to the nearest visible macrocell that is exact when
// below kLeapNear and otherwise a lower bound, at least kLeapNear (255:
// nothing visible within reach of the bound).
void leapDistance(std::uint8_t* distance, IVec3 count, ThreadPool* pool = nullptr);

// The same for rays of one direction octant (bit a of `octant` set: the
// ray goes down axis a), per Deakin & Knackstedt 2020: the distance D
// such that the box of macrocells m + t * sign, 0 <= t_a < D, reaching
// only forward from m, is empty. A cube around m is cut short by whatever
// lies behind or beside the ray; this box is not, and the leap
// (kernel::CubeExit) only ever crosses the forward faces of either. Exact
// below kLeapNear; beyond, the cube's coarse bound (at least kLeapNear,
// never more than the truth: the box lies in the cube). Same input.
void forwardLeapDistance(std::uint8_t* distance, IVec3 count, int octant, ThreadPool* pool = nullptr);

}  // namespace pvr::core
