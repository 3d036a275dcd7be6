// Where a tile's rays can first and last meet a visible macrocell, found
// once for the whole tile.
//
// Every ray walks the empty space in front of what it meets a look-up at a
// time (cast_ray.h, RayWalk); before its first visible macrocell the walks
// of neighbouring rays take nearly the same look-ups (peer scene: 40 % of
// all empty look-ups). Here the tile's rays are taken as one fat ray, a
// box around a centre ray that grows linearly with the sample index, and
// that box is marched through the distance field: while the empty cube a
// macrocell's distance proves (kernel::emptyExit) holds the whole box, no
// ray of the tile meets anything visible, so each may start its own walk
// past it; marched backwards from the far side of the visible box, it
// ends the rays' walks before the empty space behind the last thing they
// can meet. It only decides which samples in invisible macrocells the rays
// skip, so the image is unchanged beyond rounding.
#pragma once

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>

#include "kernel.h"

namespace pvr::core::kernel {

// Narrows [lo, hi] to the k in it with a + b k >= 0.
inline void keepWhereNonNegative(double a, double b, double& lo, double& hi) {
  if (b > 0) {
    lo = std::max(lo, -a / b);
  } else if (b < 0) {
    hi = std::min(hi, a / -b);
  } else if (a < 0) {
    lo = 1e300;  // nowhere
  }
}

// Rays rays[0, n) as one: sample k of every ray lies within
// radius0 + k * radiusPerStep of centre0 + k * centreStep on each axis.
struct FatRay {
  double centre0[3], centreStep[3], radius0[3], radiusPerStep[3];
};

inline FatRay fatRay(const RaySetup* rays, int n) {
  FatRay f;
  for (int a = 0; a < 3; ++a) {
    double oLo = rays[0].origin[a], oHi = oLo, sLo = rays[0].step[a], sHi = sLo;
    double oMag = 0, sMag = 0;
    for (int i = 0; i < n; ++i) {
      oLo = std::min(oLo, rays[i].origin[a]);
      oHi = std::max(oHi, rays[i].origin[a]);
      sLo = std::min(sLo, rays[i].step[a]);
      sHi = std::max(sHi, rays[i].step[a]);
      oMag = std::max(oMag, std::abs(rays[i].origin[a]));
      sMag = std::max(sMag, std::abs(rays[i].step[a]));
    }
    f.centre0[a] = 0.5 * (oLo + oHi);
    f.centreStep[a] = 0.5 * (sLo + sHi);
    // The samples' positions are computed in float (o + k d): widen by a
    // bound on that rounding, and on this arithmetic's, besides.
    constexpr double kRounding = 4 * double(FLT_EPSILON);
    f.radius0[a] = 0.5 * (oHi - oLo) + kRounding * oMag + 1e-6;
    f.radiusPerStep[a] = 0.5 * (sHi - sLo) + kRounding * sMag;
  }
  return f;
}

// At most this many look-ups per march: it stops early once the fat ray
// comes near something visible.
inline constexpr int kTileMarchLookups = 32;

// How far f can go from k = start towards k = limit > start within empty
// cubes: every position of every ray of f with k in [start, result] lies
// in an invisible macrocell or outside the brick's macrocells.
inline double marchEmpty(const KernelParams& p, const FatRay& f, double start, double limit, int mcShift) {
  double k = start;
  const double size = double(std::int64_t(1) << mcShift);
  for (int lookups = 0; lookups < kTileMarchLookups; ++lookups) {
    int m[3];
    for (int a = 0; a < 3; ++a) {
      const double c = f.centre0[a] + k * f.centreStep[a];
      m[a] = int(std::clamp(std::floor(c / size), double(p.mcFirst[a]), double(p.mcFirst[a] + p.mcCount[a] - 1)));
    }
    const int distance = p.distance[macrocellIndex(p, m)];
    if (distance == 0) break;
    // The cube of macrocells within distance - 1 of m holds only invisible
    // ones; positions in [cubeLo, cubeHi) per axis lie in it or outside the
    // brick's macrocells (the radius' slack keeps the samples off cubeHi).
    double from = k, reached = limit;
    for (int a = 0; a < 3; ++a) {
      const double cubeLo = double(m[a] - distance + 1) * size, cubeHi = double(m[a] + distance) * size;
      // centre - radius >= cubeLo and centre + radius <= cubeHi.
      keepWhereNonNegative(f.centre0[a] - f.radius0[a] - cubeLo, f.centreStep[a] - f.radiusPerStep[a], from, reached);
      keepWhereNonNegative(cubeHi - f.centre0[a] - f.radius0[a], -(f.centreStep[a] + f.radiusPerStep[a]), from, reached);
    }
    if (from > k || reached < k + 0.5) break;  // the box does not fit the cube here, or hardly moves on
    k = reached;
    if (k >= limit) return limit;
  }
  return k;
}

// The samples of a tile's rays that may lie in a visible macrocell: each
// ray's samples before `from` and after `to` lie in invisible ones.
struct TileSpan {
  std::int64_t from = 0;
  std::int64_t to = std::int64_t(1e18);
};

// Narrows a ray's samples [first, last] in the brick to those its walk
// must look at: inside the visible box (clipToVisible) and the tile's
// span. False when none are left.
inline bool clipToWalk(const KernelParams& p, const RaySetup& ray, const TileSpan& span, std::int64_t& first,
                       std::int64_t& last) {
  if (!clipToVisible(p, ray, first, last)) return false;
  first = std::max(first, span.from);
  last = std::min(last, span.to);
  return first <= last;
}

// Where a ray's walk through the brick starts and ends (walkStart below,
// for RayWalk and LevelWalk): the ray's samples in the brick (sampleRange),
// those its walk looks at (clipToWalk) and the chord's ends (chordEnds of
// first, last). startInLanes (start_lanes.h) finds the same for eight
// rays at once.
struct WalkStart {
  std::int64_t first = 0, last = -1;  // the ray's samples in the brick
  std::int64_t k = 0, end = -1;       // the first and last its walk looks at
  ChordEnds ends;
};

// The WalkStart of a ray whose samples in the brick are [first, last]
// (sampleRange); false when its walk looks at nothing (it misses the
// visible box or the tile's span).
inline bool walkStart(const KernelParams& p, const RaySetup& ray, const TileSpan& span, std::int64_t first,
                      std::int64_t last, WalkStart& at) {
  at = {first, last, first, last, {}};
  if (!clipToWalk(p, ray, span, at.k, at.end)) return false;
  at.ends = chordEnds(p, ray, first, last);
  return true;
}

// The span of rays[0, n), from marches of their fat ray through the
// distance field inwards from both ends of where it crosses the visible
// box (KernelParams::visibleLo): each ray may start its walk at `from` and
// end it at `to`. Empty (from > to) when no ray meets anything visible.
inline TileSpan tileSpan(const KernelParams& p, const RaySetup* rays, int n, int mcShift) {
  TileSpan span;
  if (n <= 0) return span;
  const FatRay f = fatRay(rays, n);
  // Where the fat ray can touch the visible box: [lo, hi].
  double lo = 0, hi = 1e18;
  for (int a = 0; a < 3; ++a) {
    if (!(p.visibleLo[a] <= p.visibleHi[a])) return span;  // nothing visible: clipToVisible ends every ray
    keepWhereNonNegative(f.centre0[a] + f.radius0[a] - p.visibleLo[a], f.centreStep[a] + f.radiusPerStep[a], lo, hi);
    keepWhereNonNegative(p.visibleHi[a] - f.centre0[a] + f.radius0[a], f.radiusPerStep[a] - f.centreStep[a], lo, hi);
  }
  if (!(lo <= hi)) return {1, 0};  // no ray of the tile meets the visible box
  const double in = marchEmpty(p, f, lo, hi, mcShift);
  if (in >= hi) return {1, 0};  // nothing visible on any ray
  // Backwards from hi: the same fat ray in k' = -k.
  FatRay back = f;
  for (int a = 0; a < 3; ++a) {
    back.centreStep[a] = -f.centreStep[a];
    back.radiusPerStep[a] = -f.radiusPerStep[a];  // radius0 - k' radiusPerStep, for k' <= 0
  }
  const double out = -marchEmpty(p, back, -hi, -in, mcShift);
  span.from = std::int64_t(std::floor(in));
  span.to = std::int64_t(std::ceil(std::min(out, 1e18)));
  return span;
}

}  // namespace pvr::core::kernel
