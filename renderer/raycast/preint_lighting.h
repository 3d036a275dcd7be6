// Lighting a pre-integrated segment: shade() at the two points
// preint::segment() names, centre -+ spread, and the two colours averaged
// (the Gauss rule for the emission's first two moments). Lit at the
// emission's centroid alone, a segment's lighting error was the largest
// term of pre-integration's error on shaded scenes, larger than point
// sampling's at the same step (bench/results/preintegration.txt).
#pragma once

#include <algorithm>

#include "kernel.h"

namespace pvr::core::kernel {

// The segment from step t0 to t0 + span of ray, colour c (premultiplied,
// unlit), centre and spread in fractions of the segment.
template <typename T>
[[gnu::always_inline]] inline Rgba shadeSegment(const T* v, const KernelParams& p, const RaySetup& ray, float t0,
                                                float span, float centre, float spread, const Rgba& c) {
  auto lit = [&](float fraction) __attribute__((always_inline)) {
    const float t = t0 + span * fraction;
    return shade(v, p, ray, float(ray.origin[0]) + t * float(ray.step[0]),
                 float(ray.origin[1]) + t * float(ray.step[1]), float(ray.origin[2]) + t * float(ray.step[2]), c);
  };
  if (!(spread > 0)) return lit(centre);
  const Rgba front = lit(std::max(centre - spread, 0.0f)), back = lit(std::min(centre + spread, 1.0f));
  return {0.5f * (front.r + back.r), 0.5f * (front.g + back.g), 0.5f * (front.b + back.b), c.a};
}

}  // namespace pvr::core::kernel
