// The batched plain kernel (renderer/raycast/kernel_batch.h) and the
// one-at-a-time loop (cast_ray.h, runScalar) over the same samples of one
// ray, for the tests that compare them (batch_kernel_test.cpp,
// batch_tail_test.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "raycast/cast_ray.h"
#include "raycast/macrocells.h"
#include "reference.h"

#ifdef PVR_HAVE_BATCH_KERNEL

namespace pvr::core::test {

struct Run {
  kernel::Accumulator acc;
  std::uint64_t samples = 0;
  std::int64_t stoppedAt = 0;  // the batched run's `start` when it returned
  bool terminated = false;
};

// Samples [first, last) one at a time (kPower: specular_power.h).
template <typename V, bool kShaded, int kPower = kernel::kTablePower>
Run scalarRun(const KernelParams& p, const RaySetup& ray, std::int64_t first, std::int64_t last) {
  Run r;
  r.terminated = kernel::runScalar<V, kShaded, false, kPower>(p, ray, first, last, r.acc, r.samples);
  return r;
}

// Samples [first, last) batched, and whatever the batches leave one at a
// time (nothing since the run's tail is a batch: batch_tail_test.cpp).
template <typename V, bool kShaded, int kPower = kernel::kTablePower>
Run batchedRun(const KernelParams& p, const RaySetup& ray, std::int64_t first, std::int64_t last) {
  Run r;
  std::int64_t start = first;
  r.terminated = kernel::runBatched<V, kShaded, kPower>(p, ray, start, last, r.acc, r.samples);
  r.stoppedAt = start;
  if (!r.terminated)
    r.terminated = kernel::runScalar<V, kShaded, false, kPower>(p, ray, start, last, r.acc, r.samples);
  return r;
}

// The largest difference of the four channels.
inline double difference(const kernel::Accumulator& a, const kernel::Accumulator& b) {
  return std::max({std::abs(a.r - b.r), std::abs(a.g - b.g), std::abs(a.b - b.b), std::abs(a.a - b.a)});
}

// A ray along +x at (y, z) of a grid, in index units, lit from +z.
inline RaySetup alongX(double y, double z, double step) {
  RaySetup r{};
  r.origin[0] = 0;
  r.origin[1] = y;
  r.origin[2] = z;
  r.step[0] = step;
  r.invStep[0] = 1 / step;
  r.leapPerMacrocell = MacrocellGrid::kSize / step;
  r.light[2] = r.halfway[2] = 1;
  return r;
}

// A perspective view of `grid` from below one corner, size x size pixels,
// its rays crossing the grid at an angle to every axis.
inline Camera obliqueView(const GridGeometry& grid, int size) {
  const Vec3 c = grid.center();
  return makeCamera(Projection::kPerspective, c - normalize(Vec3{0.3, 1, 0.5}) * 70.0, c, {0, 0, 1}, 40, size, size);
}

// A scalar type and the affine map from [0, 1] onto the values its tests use.
struct ScaledType {
  ScalarType type;
  double scale, offset;
};

}  // namespace pvr::core::test

#endif
