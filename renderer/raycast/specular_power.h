// The specular power x^shininess of kernel::shade() and shadeQuads()
// (Blinn-Phong's (n.h)^shininess, x in [0, 1]), and how the shaded kernel
// is told which way to raise it: a template parameter, kPower, chosen once
// per frame where the kernel is picked (raycaster.cpp: pickKernel()), so
// the per-sample loop does not branch on the shininess. Pre-integrated
// kernels, the kernel that picks the step per region and the kernel of
// several volumes keep the table.
//
//   kTablePower (0)   the interpolated table of 2048 values (kernel_setup.cpp:
//                     specularTable()), for any shininess;
//   b in 1..8         a whole shininess n, 1 <= n < 2^b, by b steps of
//                     binary exponentiation from the highest bit down:
//                     r = r * r * (bit k of n ? x : 1).
//
// Why: the table look-up of eight lit samples took a store, a gather and
// its shuffles, and sat in the lit batch's chain of dependent steps; the
// steps are three vector operations each. The factor of a step is
// max(x, floor[k]) (floor[k] 0 where bit k of n is set, 1 where clear:
// KernelParams::powerFloor), so no lane and no sample branches on n.
// Steps over leading clear bits keep r = 1 exactly, so a kernel of b steps
// gives the same bits for every n below 2^b (pickKernel() rounds b up to
// a few instantiations); and no partial power is smaller than the result,
// so no step falls into denormals (slow) unless x^n itself does.
//
// Accuracy: a squaring doubles the relative error it is given and adds a
// rounding (2^-24), a product by x adds one, a product by 1 is exact: x^n
// carries less than 2 n 2^-24 relative error (24: 2.9e-6; 255: 3.0e-5),
// where the table's linear interpolation erred up to about
// n (n - 1) / (8 2047^2) relative near x = 1 (24: 1.6e-5; 255: 9.5e-4).
// The scalar and the vector forms multiply in the same order, so they give
// the same bits.
#pragma once

#include <algorithm>

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif

namespace pvr::core::kernel {

// kPower of a kernel that reads the table.
inline constexpr int kTablePower = 0;
// The most steps: whole shininesses up to 2^kPowerBits - 1 take them.
inline constexpr int kPowerBits = 8;

// The steps a whole shininess in [1, 2^kPowerBits) needs (its bit length),
// or kTablePower for any other (then the table applies).
inline int powerBits(double shininess) {
  if (!(shininess >= 1.0 && shininess < double(1 << kPowerBits))) return kTablePower;
  const int n = int(shininess);
  if (double(n) != shininess) return kTablePower;
  int bits = 0;
  while (n >> bits) ++bits;
  return bits;
}

// powerFloor (KernelParams) of a whole shininess n: floor[k] is 0 where
// bit k of n is set, 1 where it is clear.
inline void setPowerFloor(int n, float floor[kPowerBits]) {
  for (int k = 0; k < kPowerBits; ++k) floor[k] = (n >> k) & 1 ? 0.0f : 1.0f;
}

// x^n, x in [0, 1], by kBits steps (see above).
template <int kBits>
[[gnu::always_inline]] inline float powerBySteps(float x, const float* floor) {
  static_assert(kBits >= 1 && kBits <= kPowerBits);
  float r = std::max(x, floor[kBits - 1]);
  for (int k = kBits - 2; k >= 0; --k) {
    const float square = r * r;
    r = square * std::max(x, floor[k]);
  }
  return r;
}

#if defined(__AVX2__) && defined(__FMA__)
// powerBySteps() of eight lanes.
template <int kBits>
[[gnu::always_inline]] inline __m256 powerBySteps8(__m256 x, const float* floor) {
  static_assert(kBits >= 1 && kBits <= kPowerBits);
  __m256 r = _mm256_max_ps(x, _mm256_set1_ps(floor[kBits - 1]));
  for (int k = kBits - 2; k >= 0; --k)
    r = _mm256_mul_ps(_mm256_mul_ps(r, r), _mm256_max_ps(x, _mm256_set1_ps(floor[k])));
  return r;
}
#endif

}  // namespace pvr::core::kernel
