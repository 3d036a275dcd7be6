// castRay: march one ray through one brick, skipping invisible macrocells.
//
// Instantiated per scalar type, shading and pre-integration by
// raycaster.cpp; nothing in here branches on configuration at run time.
#pragma once

#include "kernel.h"

namespace pvr::core {

namespace kernel {

// Samples [start, exit) of a visible run, one at a time. Returns true when
// the ray reached the early-termination opacity.
template <typename T, bool kShaded, bool kPreintegrated>
inline bool runScalar(const KernelParams& p, const RaySetup& ray, std::int64_t start,
                      std::int64_t exit, Rgba& acc, std::uint64_t& samples) {
  const T* v = static_cast<const T*>(p.voxels);
  const float o0 = float(ray.origin[0]), o1 = float(ray.origin[1]), o2 = float(ray.origin[2]);
  const float d0 = float(ray.step[0]), d1 = float(ray.step[1]), d2 = float(ray.step[2]);
  float front = 0;
  if constexpr (kPreintegrated)
    front = around(v, p, o0 + float(start) * d0, o1 + float(start) * d1, o2 + float(start) * d2);
  for (std::int64_t s = start; s < exit; ++s) {
    const float x0 = o0 + float(s) * d0, x1 = o1 + float(s) * d1, x2 = o2 + float(s) * d2;
    Rgba c;
    if constexpr (kPreintegrated) {
      const float back = around(v, p, x0 + d0, x1 + d1, x2 + d2);
      c = finite<T>(front) && finite<T>(back) ? classify2D(p, front, back) : Rgba{};
      front = back;
    } else {
      const float value = trilinear(v, p, x0, x1, x2, p.ownCellLo, p.ownCellHi);
      c = finite<T>(value) ? classify1D(p, value) : Rgba{};
    }
    ++samples;
    if constexpr (kShaded) {
      if (!(c.a > 0)) continue;
      c = shade(v, p, ray, x0, x1, x2, c);
    }
    const float t = 1.0f - acc.a;
    acc.r += t * c.r;
    acc.g += t * c.g;
    acc.b += t * c.b;
    acc.a += t * c.a;
    if (acc.a >= p.earlyTermination) return true;
  }
  return false;
}


}  // namespace kernel

template <typename T, bool kShaded, bool kPreintegrated>
RayResult castRay(const KernelParams& p, const RaySetup& ray, int mcShift) {
  RayResult out;
  std::int64_t first, last;
  if (!kernel::sampleRange(p, ray, first, last)) return out;
  out.hit = true;

  const float o0 = float(ray.origin[0]), o1 = float(ray.origin[1]), o2 = float(ray.origin[2]);
  const float d0 = float(ray.step[0]), d1 = float(ray.step[1]), d2 = float(ray.step[2]);
  Rgba acc;
  std::int64_t done = first;  // next sample not yet composited or skipped
  std::int64_t k = first;
  while (k <= last) {
    // Which macrocell holds sample k, and where does its run of equally
    // visible macrocells end?
    const float u0 = o0 + float(k) * d0, u1 = o1 + float(k) * d1, u2 = o2 + float(k) * d2;
    int m[3] = {std::clamp(int(u0) >> mcShift, p.mcFirst[0], p.mcFirst[0] + p.mcCount[0] - 1),
                std::clamp(int(u1) >> mcShift, p.mcFirst[1], p.mcFirst[1] + p.mcCount[1] - 1),
                std::clamp(int(u2) >> mcShift, p.mcFirst[2], p.mcFirst[2] + p.mcCount[2] - 1)};
    bool visible;
    const std::int64_t exit = kernel::runExit(p, ray, m, k, last, mcShift, visible);
    if (!visible) {
      k = exit;
      continue;
    }
    // A pre-integrated segment runs from one sample to the next: when the
    // sample before this run was skipped, its segment ends in here.
    std::int64_t start = k;
    if constexpr (kPreintegrated) start = (done < k) ? std::max(first, k - 1) : k;
    if (kernel::runScalar<T, kShaded, kPreintegrated>(p, ray, start, exit, acc, out.samples)) break;
    done = exit;
    k = exit;
  }
  out.colour = acc;
  return out;
}

}  // namespace pvr::core
