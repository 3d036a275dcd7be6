// The empty-space look-ups of castRays' rays in the eight lanes of AVX-512
// vectors (walkInLanes): pastEmpty()'s position, macrocell and
// distance byte, and CubeExit::exit()'s leap, each lane with exactly the
// scalar arithmetic (the same fused multiply-adds, truncations and
// rounding up), so every lane lands on the sample its ray's scalar walk
// would, and the rays take the same chunks: the same images, bit for bit.
//
// Why two vectors of eight lanes of 512 bits: a look-up is one chain of
// dependent arithmetic and a load (~100 cycles in lanes). The scalar walks
// of four rays by turns overlap their four chains; one vector of four
// lanes made the four into a single longer chain and was no faster. Eight
// lanes take about twice the look-ups per chain (peer scene: the walk's
// own CPU time 47-48 ms a frame against 53-68 ms by turns), and two such
// vectors taken by turns overlap their chains (bench/results/walk.txt).
#pragma once

#include "kernel.h"

#ifdef PVR_HAVE_WALK_LANES

#include <immintrin.h>

#include <cstdint>

#include "preint_lanes.h"

namespace pvr::core::kernel {

inline constexpr int kWalkLanes = 8;
// Vectors of look-ups taken by turns: two chains that overlap in the CPU
// (peer scene: 1-2 % less CPU a frame than one vector of eight rays).
inline constexpr int kWalkVectors = 2;
static_assert(kRaysAtOnce == kWalkVectors * kWalkLanes, "castRays takes its rays' look-ups in kWalkVectors vectors");

// Eight walks' look-ups. Masked intrinsics with every lane set
// (preint::kAll): the unmasked forms start from GCC 12's "undefined"
// vectors, which -Wmaybe-uninitialized reports.
class WalkLanes {
 public:
  // The macrocell grid's clamps and strides, the same for every lane.
  WalkLanes(const KernelParams& p, int mcShift) {
    shift_ = _mm_cvtsi32_si128(mcShift);
    for (int a = 0; a < 3; ++a) {
      lo_[a] = _mm512_set1_epi64(p.mcFirst[a]);
      hi_[a] = _mm512_set1_epi64(p.mcFirst[a] + p.mcCount[a] - 1);
    }
    // macrocellIndex() as m0 + m1 c0 + m2 c0 c1 less the first macrocell's
    // (the same integer: two multiplies side by side, not in a chain).
    const std::int64_t c0 = p.mcCount[0], c01 = c0 * p.mcCount[1];
    strideY_ = _mm512_set1_epi64(c0);
    strideZ_ = _mm512_set1_epi64(c01);
    first_ = _mm512_set1_epi64(p.mcFirst[0] + p.mcFirst[1] * c0 + p.mcFirst[2] * c01);
  }

  // Lane i walks the ray whose origin and step in float are o and d,
  // leaping by `cube` through `field`, from sample k to sample `end` (a
  // walk's, LeapingWalk::toLane).
  void set(int i, const float* o, const float* d, const CubeExit& cube, const std::uint8_t* field,
           std::int64_t k, std::int64_t end) {
    for (int a = 0; a < 3; ++a) {
      o_[a][i] = o[a];
      d_[a][i] = d[a];
      scale_[a][i] = cube.scale(a);
      base_[a][i] = cube.base(a);
      sign_[a][i] = cube.sign(a);
    }
    field_[i] = field;
    k_[i] = k;
    end_[i] = end;
  }
  __m512i start() const { return _mm512_load_si512(k_); }
  __m512i end() const { return _mm512_load_si512(end_); }

  // Where each lane's walk goes on from sample k: k where its macrocell is
  // visible, else past the empty box its field proves, as pastEmpty() and
  // CubeExit::exit(). Every lane must have been set.
  [[gnu::always_inline]] __m512i next(__m512i k) const {
    using preint::kAll;
    // Positions o + float(k) d in one rounding (the scalar form contracts
    // to an FMA), truncated, macrocells clamped into the brick's.
    const __m256 kf = _mm512_maskz_cvtepi64_ps(kAll, k);
    __m512i m[3];
    __m512d mD[3];
    for (int a = 0; a < 3; ++a) {
      const __m256 u = _mm256_fmadd_ps(kf, _mm256_load_ps(d_[a]), _mm256_load_ps(o_[a]));
      const __m512i cell = _mm512_maskz_sra_epi64(kAll, _mm512_maskz_cvttps_epi64(kAll, u), shift_);
      m[a] = _mm512_maskz_min_epi64(kAll, _mm512_maskz_max_epi64(kAll, cell, lo_[a]), hi_[a]);
      mD[a] = _mm512_maskz_cvtepi64_pd(kAll, m[a]);
    }
    const __m512i index =
        _mm512_sub_epi64(_mm512_add_epi64(_mm512_add_epi64(m[0], _mm512_maskz_mul_epu32(kAll, m[1], strideY_)),
                                          _mm512_maskz_mul_epu32(kAll, m[2], strideZ_)),
                         first_);
    // The distance bytes, each from the aligned 64-bit word that holds it:
    // that word never reaches past the page the byte lies in.
    const __m512i at = _mm512_add_epi64(_mm512_load_si512(field_), index);
    const __m512i words = _mm512_mask_i64gather_epi64(
        _mm512_setzero_si512(), kAll, _mm512_maskz_andnot_epi64(kAll, _mm512_set1_epi64(7), at), nullptr, 1);
    const __m512i byteShift = _mm512_maskz_slli_epi64(kAll, _mm512_and_si512(at, _mm512_set1_epi64(7)), 3);
    const __m512i distance =
        _mm512_and_si512(_mm512_maskz_srlv_epi64(kAll, words, byteShift), _mm512_set1_epi64(0xff));
    // CubeExit::exit(): each face m + sign distance, exact in double, then
    // the same FMA per axis; the least of the three and 1e18 (its 1e300
    // start is never the least), rounded up in the conversion.
    const __m512d distanceD = _mm512_maskz_cvtepi64_pd(kAll, distance);
    __m512d v[3];
    for (int a = 0; a < 3; ++a)
      v[a] = _mm512_fmadd_pd(_mm512_fmadd_pd(_mm512_load_pd(sign_[a]), distanceD, mD[a]),
                             _mm512_load_pd(scale_[a]), _mm512_load_pd(base_[a]));
    const __m512d exitK = _mm512_maskz_min_pd(kAll, _mm512_maskz_min_pd(kAll, v[0], v[1]),
                                              _mm512_maskz_min_pd(kAll, v[2], _mm512_set1_pd(1e18)));
    const __m512i up = _mm512_maskz_cvt_roundpd_epi64(kAll, exitK, _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC);
    const __m512i leap = _mm512_maskz_max_epi64(kAll, _mm512_add_epi64(k, _mm512_set1_epi64(1)), up);
    return _mm512_mask_mov_epi64(leap, _mm512_cmpeq_epi64_mask(distance, _mm512_setzero_si512()), k);
  }

 private:
  alignas(32) float o_[3][kWalkLanes], d_[3][kWalkLanes];
  // CubeExit's terms; the sign in double, so that a face is one exact FMA.
  alignas(64) double scale_[3][kWalkLanes], base_[3][kWalkLanes], sign_[3][kWalkLanes];
  alignas(64) const std::uint8_t* field_[kWalkLanes];
  alignas(64) std::int64_t k_[kWalkLanes], end_[kWalkLanes];
  __m128i shift_;
  __m512i lo_[3], hi_[3], strideY_, strideZ_, first_;
};

// castRays' walks (RayWalk) walk[0, n), going[i] when walk i has started
// and is not done, to their ends: each round one vector look-up for each
// eight of them; the walks whose look-up lands past their end are done,
// those that find their macrocell visible take a chunk (Walk::chunkAt),
// the others leap on in their lanes. Each walk takes the look-ups, leaps
// and chunks RayWalk::step would, in the same order, so its result is
// castRay's.
template <typename Walk>
void walkInLanes(const KernelParams& p, const RaySetup* rays, int n, int mcShift, Walk* walk, const bool* going,
                 RayResult* out) {
  // live[g] bit i: walk g * kWalkLanes + i is going.
  unsigned live[kWalkVectors] = {}, all = 0;
  for (int i = 0; i < n; ++i) {
    live[i / kWalkLanes] |= unsigned(going[i]) << (i % kWalkLanes);
    all |= unsigned(going[i]) << i;
  }
  if (!all) return;
  // Lanes without a walk (absent, or done at the start) look up with a
  // live walk's ray; their results are never read.
  const int any = __builtin_ctz(all);
  WalkLanes lanes[kWalkVectors] = {{p, mcShift}, {p, mcShift}};
  __m512i k[kWalkVectors], end[kWalkVectors];
  for (int g = 0; g < kWalkVectors; ++g) {
    for (int i = 0; i < kWalkLanes; ++i) {
      const int r = g * kWalkLanes + i;
      walk[(all >> r) & 1 ? r : any].toLane(lanes[g], i);
    }
    k[g] = lanes[g].start();
    end[g] = lanes[g].end();
  }
  auto anyLive = [&] {
    unsigned on = 0;
    for (const unsigned l : live) on |= l;
    return on;
  };
  alignas(64) std::int64_t at[kWalkLanes];
  while (anyLive()) {
    // Every vector's look-up first, so that their chains overlap.
    __m512i next[kWalkVectors];
    for (int g = 0; g < kWalkVectors; ++g) next[g] = lanes[g].next(k[g]);
    for (int g = 0; g < kWalkVectors; ++g) {
      const unsigned visible = unsigned(_mm512_cmpeq_epi64_mask(next[g], k[g])) & live[g];
      const unsigned past = unsigned(_mm512_cmpgt_epi64_mask(next[g], end[g])) & live[g] & ~visible;
      k[g] = next[g];
      if (!(visible | past)) continue;  // all leapt, and none past its end
      Walk* w = walk + g * kWalkLanes;
      RayResult* o = out + g * kWalkLanes;
      const RaySetup* r = rays + g * kWalkLanes;
      for (unsigned bits = past; bits; bits &= bits - 1) w[__builtin_ctz(bits)].finish(o[__builtin_ctz(bits)]);
      live[g] &= ~past;
      _mm512_store_si512(at, k[g]);
      for (unsigned bits = visible; bits; bits &= bits - 1) {
        const int i = __builtin_ctz(bits);
        if (w[i].chunkAt(at[i], p, r[i], mcShift, o[i]))
          k[g] = _mm512_mask_set1_epi64(k[g], __mmask8(1u << i), w[i].at());
        else
          live[g] &= ~(1u << i);
      }
    }
  }
}

}  // namespace pvr::core::kernel

#endif
