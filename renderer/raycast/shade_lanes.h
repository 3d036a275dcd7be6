// Lighting the eight samples of a batch at once, for runBatched
// (kernel_batch.h): the same gradient and Blinn-Phong as kernel::shade(),
// in structure-of-arrays form, one vector lane per sample.
//
// Lit one at a time, a sample's interior gradient read its 32 nodes with
// 32 scalar loads and conversions, and its normalise and specular look-up
// ran in scalar arithmetic: most of a shaded frame. Here each lane reads
// the 32 nodes in 12 loads (four rows of four nodes along x, eight pairs,
// batch_loads.h), and every step after the loads is one vector
// instruction for all eight samples. Lanes outside the
// interior form (near the domain's faces or the stored box's) take the
// scalar kernel::gradient(), so whole volume and bricks still read the
// same nodes for the same sample (kernel::interiorGradient()).
#pragma once

#if defined(__AVX2__) && defined(__FMA__)

#include <immintrin.h>

#include <cfloat>
#include <cstdint>

#include "batch_loads.h"
#include "kernel.h"
#include "kernel_batch_over.h"

namespace pvr::core::kernel {

// The lanes whose position u lies where kernel::interiorGradient() applies
// (one voxel inside the domain, the cell's 4x4x4 nodes stored), as a mask
// of all-ones lanes; cell gets int(u), the cell that form reads around.
[[gnu::always_inline]] inline __m256 interiorLanes8(const KernelParams& p, const __m256 u[3], __m256i cell[3]) {
  const __m256 one = _mm256_set1_ps(1.0f);
  __m256 inside = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
  for (int a = 0; a < 3; ++a) {
    cell[a] = _mm256_cvttps_epi32(u[a]);
    const __m256 within = _mm256_and_ps(_mm256_cmp_ps(u[a], one, _CMP_GE_OQ),
                                        _mm256_cmp_ps(u[a], _mm256_set1_ps(p.domainMax[a] - 1.0f), _CMP_LE_OQ));
    // storedCellLo <= cell - 1 and cell + 1 <= storedCellHi.
    const __m256i stored = _mm256_andnot_si256(
        _mm256_or_si256(_mm256_cmpgt_epi32(_mm256_set1_epi32(p.storedCellLo[a] + 1), cell[a]),
                        _mm256_cmpgt_epi32(cell[a], _mm256_set1_epi32(p.storedCellHi[a] - 1))),
        _mm256_set1_epi32(-1));
    inside = _mm256_and_ps(inside, _mm256_and_ps(within, _mm256_castsi256_ps(stored)));
  }
  return inside;
}

// The gradients at the eight positions u (index space) of the lanes in
// `wanted` (bit j: lane j), as kernel::gradient() computes them, up to
// rounding; the other lanes' are unspecified (finite or not). g in world
// units, one vector per axis.
template <typename T, bool kShifted = false>
[[gnu::always_inline]] inline void gradient8(const T* v, const KernelParams& p, const __m256 u[3], unsigned wanted,
                                             __m256 g[3]) {
  // Every lane where the interior form applies is computed by it, wanted
  // or not: its loads then hang on the positions alone, not on `wanted`
  // (the classification's chain), and start while the batch is still
  // being reconstructed and classified.
  __m256i cell[3];
  const __m256i inLane = _mm256_castps_si256(interiorLanes8(p, u, cell));
  const unsigned interior = unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(inLane)));
  if (interior) {
    // Lanes not computed here read around the first lane that is, so every
    // load stays in the stored box.
    const __m256i index0 = voxelIndex8(IndexLanes<kShifted>(p), cell[0], cell[1], cell[2]);
    const __m256i firstLane =
        _mm256_permutevar8x32_epi32(index0, _mm256_set1_epi32(__builtin_ctz(interior)));
    alignas(32) std::int32_t index[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(index), _mm256_blendv_epi8(firstLane, index0, inLane));
    const __m256 fx = _mm256_sub_ps(u[0], _mm256_cvtepi32_ps(cell[0]));
    const __m256 fy = _mm256_sub_ps(u[1], _mm256_cvtepi32_ps(cell[1]));
    const __m256 fz = _mm256_sub_ps(u[2], _mm256_cvtepi32_ps(cell[2]));
    const std::int64_t sy = p.strideY, sz = p.strideZ;
    // Rows along x at (dy, dz) = (0,0), (1,0), (0,1), (1,1): nodes x - 1 ..
    // x + 2; x0 and x1 are the cell's own corners, which the y and z
    // differences reuse.
    __m256 xm[4], x0[4], x1[4], x2[4];
    for (int r = 0; r < 4; ++r) {
      __m256 q[4];
      loadQuads8(v, index, (r & 1) * sy + (r >> 1) * sz - 1, q);
      xm[r] = q[0];
      x0[r] = q[1];
      x1[r] = q[2];
      x2[r] = q[3];
    }
    // Nodes y - 1 and y + 2 at dz = 0, 1, and z - 1 and z + 2 at dy = 0, 1
    // (pairs: dx = 0 and 1).
    __m256 ym[2][2], y2[2][2], zm[2][2], z2[2][2];
    for (int h = 0; h < 2; ++h) {
      loadPairs8(v, index, -sy + h * sz, ym[h][0], ym[h][1]);
      loadPairs8(v, index, 2 * sy + h * sz, y2[h][0], y2[h][1]);
      loadPairs8(v, index, -sz + h * sy, zm[h][0], zm[h][1]);
      loadPairs8(v, index, 2 * sz + h * sy, z2[h][0], z2[h][1]);
    }
    // The cell's corner (dx, dy, dz).
    auto corner = [&](int dx, int dy, int dz) __attribute__((always_inline)) {
      return dx ? x1[dy + 2 * dz] : x0[dy + 2 * dz];
    };
    // (1 - f) (after - before) + f (far - near): a central difference at
    // the two nodes either side, interpolated (interiorGradient()).
    auto difference = [](__m256 f, __m256 before, __m256 near, __m256 after, __m256 far)
                          __attribute__((always_inline)) {
      return _mm256_fmadd_ps(f, _mm256_sub_ps(far, near),
                             _mm256_mul_ps(_mm256_sub_ps(_mm256_set1_ps(1.0f), f), _mm256_sub_ps(after, before)));
    };
    auto bilinear = [](__m256 w1, __m256 w2, __m256 a00, __m256 a10, __m256 a01, __m256 a11)
                        __attribute__((always_inline)) { return lerp8(lerp8(a00, a10, w1), lerp8(a01, a11, w1), w2); };
    __m256 dX[4], dY[4], dZ[4];
    for (int r = 0; r < 4; ++r) dX[r] = difference(fx, xm[r], x0[r], x1[r], x2[r]);
    for (int dz = 0; dz < 2; ++dz)
      for (int dx = 0; dx < 2; ++dx)
        dY[dx + 2 * dz] = difference(fy, ym[dz][dx], corner(dx, 0, dz), corner(dx, 1, dz), y2[dz][dx]);
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx)
        dZ[dx + 2 * dy] = difference(fz, zm[dy][dx], corner(dx, dy, 0), corner(dx, dy, 1), z2[dy][dx]);
    g[0] = _mm256_mul_ps(bilinear(fy, fz, dX[0], dX[1], dX[2], dX[3]), _mm256_set1_ps(0.5f * p.invSpacing[0]));
    g[1] = _mm256_mul_ps(bilinear(fx, fz, dY[0], dY[1], dY[2], dY[3]), _mm256_set1_ps(0.5f * p.invSpacing[1]));
    g[2] = _mm256_mul_ps(bilinear(fx, fy, dZ[0], dZ[1], dZ[2], dZ[3]), _mm256_set1_ps(0.5f * p.invSpacing[2]));
  } else {
    g[0] = g[1] = g[2] = _mm256_setzero_ps();
  }
  // The rest one at a time (rare: a voxel from the domain's or the stored
  // box's faces).
  if (const unsigned rest = wanted & ~interior) {
    alignas(32) float at[3][8], out[3][8];
    for (int a = 0; a < 3; ++a) {
      _mm256_store_ps(at[a], u[a]);
      _mm256_store_ps(out[a], g[a]);
    }
    for (unsigned lanes = rest; lanes; lanes &= lanes - 1) {
      const int j = __builtin_ctz(lanes);
      float one[3];
      gradient(v, p, at[0][j], at[1][j], at[2][j], one);
      for (int a = 0; a < 3; ++a) out[a][j] = one[a];
    }
    for (int a = 0; a < 3; ++a) g[a] = _mm256_load_ps(out[a]);
  }
}

// The opacities of the eight samples in lane order (quad j holds samples j
// and j + 4, kernel_batch_over.h).
[[gnu::always_inline]] inline __m256 alphaLanes(const Quads& c) {
  const __m256 a01 = _mm256_shuffle_ps(c.q[0], c.q[1], _MM_SHUFFLE(3, 3, 3, 3));  // a0 a0 a1 a1 | a4 a4 a5 a5
  const __m256 a23 = _mm256_shuffle_ps(c.q[2], c.q[3], _MM_SHUFFLE(3, 3, 3, 3));
  return _mm256_shuffle_ps(a01, a23, _MM_SHUFFLE(2, 0, 2, 0));  // a0 a1 a2 a3 | a4 a5 a6 a7
}

// The batch's samples at positions u, colours c, lit as kernel::shade()
// lights each: those with opacity > 0; the others are left as they are.
// kPower: how nh^shininess is raised (specular_power.h).
template <typename T, int kPower = kTablePower, bool kShifted = false>
[[gnu::always_inline]] inline void shadeQuads(const T* v, const KernelParams& p, const RaySetup& ray,
                                              const __m256 u[3], Quads& c) {
  const __m256 visible = _mm256_cmp_ps(alphaLanes(c), _mm256_setzero_ps(), _CMP_GT_OQ);
  const unsigned wanted = unsigned(_mm256_movemask_ps(visible));
  if (!wanted) return;
  __m256 g[3];
  gradient8<T, kShifted>(v, p, u, wanted, g);
  // Blinn-Phong, two-sided; a zero or non-finite gradient is lit head-on.
  const __m256 gg = _mm256_fmadd_ps(g[2], g[2], _mm256_fmadd_ps(g[1], g[1], _mm256_mul_ps(g[0], g[0])));
  const __m256 lighted = _mm256_and_ps(_mm256_cmp_ps(gg, _mm256_set1_ps(1e-20f), _CMP_GT_OQ),
                                       _mm256_cmp_ps(gg, _mm256_set1_ps(FLT_MAX), _CMP_LE_OQ));
  const __m256 inv = _mm256_div_ps(_mm256_set1_ps(1.0f), _mm256_sqrt_ps(gg));
  auto dot = [&](const float* w) __attribute__((always_inline)) {
    const __m256 d = _mm256_fmadd_ps(g[2], _mm256_set1_ps(w[2]),
                                     _mm256_fmadd_ps(g[1], _mm256_set1_ps(w[1]), _mm256_mul_ps(g[0], _mm256_set1_ps(w[0]))));
    return _mm256_andnot_ps(_mm256_set1_ps(-0.0f), _mm256_mul_ps(d, inv));  // |g.w| / |g|
  };
  const __m256 nl = dot(ray.light), nh = dot(ray.halfway);
  const __m256 ambient = _mm256_set1_ps(p.ambient), diffuse = _mm256_set1_ps(p.diffuse);
  const __m256 lit = _mm256_blendv_ps(_mm256_add_ps(ambient, diffuse), _mm256_fmadd_ps(diffuse, nl, ambient), lighted);
  // nh^shininess as kernel::shade() raises it: by steps (specular_power.h)
  // or from the table, where lanes not lighted look up entry 0. Those add
  // nothing.
  __m256 power;
  if constexpr (kPower == kTablePower) {
    const __m256 x = _mm256_and_ps(
        _mm256_mul_ps(_mm256_min_ps(nh, _mm256_set1_ps(1.0f)), _mm256_set1_ps(float(kSpecularTableSize - 1))), lighted);
    const __m256i entry = _mm256_min_epi32(_mm256_cvttps_epi32(x), _mm256_set1_epi32(kSpecularTableSize - 2));
    alignas(32) std::int32_t e[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(e), entry);
    __m256 t0, t1;
    loadPairs8(p.specularTable, e, 0, t0, t1);
    power = lerp8(t0, t1, _mm256_sub_ps(x, _mm256_cvtepi32_ps(entry)));
  } else {
    power = powerBySteps8<kPower>(_mm256_min_ps(nh, _mm256_set1_ps(1.0f)), p.powerFloor);
  }
  const __m256 spec = _mm256_and_ps(_mm256_mul_ps(_mm256_set1_ps(p.specular), power), lighted);
  // Invisible lanes keep their colour: times 1, plus 0.
  const __m256 scale = _mm256_blendv_ps(_mm256_set1_ps(1.0f), lit, visible);
  const __m256 add = _mm256_and_ps(spec, visible);
  // Per quad: rgb * lit + spec * a, alpha unchanged.
  for (int j = 0; j < 4; ++j) {
    const __m256i pick = _mm256_setr_epi32(j, j, j, j, j + 4, j + 4, j + 4, j + 4);
    const __m256 s = _mm256_blend_ps(_mm256_permutevar8x32_ps(scale, pick), _mm256_set1_ps(1.0f), 0x88);
    const __m256 a = _mm256_blend_ps(_mm256_permutevar8x32_ps(add, pick), _mm256_setzero_ps(), 0x88);
    c.q[j] = _mm256_fmadd_ps(a, _mm256_permute_ps(c.q[j], 0xFF), _mm256_mul_ps(c.q[j], s));
  }
}

}  // namespace pvr::core::kernel

#endif
