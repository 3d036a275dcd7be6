// Classifying and compositing eight consecutive samples of one ray at once,
// for runBatched (kernel_batch.h).
//
// The one-at-a-time "over" is a chain: each sample waits for the opacity
// the previous one left (a subtraction and a multiply-add in double, ~8
// cycles a sample). "Over" is associative, so the eight samples of a batch
// are first composited with each other in a tree of three levels (four,
// two, then one "over" of four floats each), and the batch's colour joins
// the ray's accumulator in one update: one link of the chain per eight
// samples.
//
// Accuracy of the tree in float: f over b = f + (1 - f.a) b adds positive
// terms only, so each level rounds relative to its result (a few ulp of the
// batch's colour and opacity), where a product of transmittances would
// lose the opacity of faint samples in 1 - T (an ulp of 1, 6e-8, against
// opacities of 1e-3). 1 - f.a is exact for f.a >= 0.5 and within 6e-8 of
// the exact value below. The accumulator stays in double (kernel::
// Accumulator explains why a float sum stalls), so a long ray of faint
// samples reaches its opacity: tests/renderer/batch_kernel_test.cpp.
#pragma once

#if defined(__AVX2__) && defined(__FMA__)

#include <immintrin.h>

#include <cstdint>

#include "kernel.h"

namespace pvr::core::kernel {

// Eight premultiplied RGBA samples s0..s7 as four "quads": quad j holds
// sample j in its low 128 bits and sample j + 4 in its high 128 bits, so
// the tree's first two levels work on both halves at once.
struct Quads {
  __m256 q[4];
};

// Table entries e and e + 1 of the eight lanes (Rgba is four floats: the
// two entries are 32 contiguous bytes, one load per lane), interpolated
// with the lanes' weights: the same lerp as classify1D.
[[gnu::always_inline]] inline Quads classifyQuads(const Rgba* table, __m256i entry, __m256 weight) {
  // The entries' byte offsets, read back as scalars: extracting the eight
  // lanes from a register took the shuffle port, which the batch is short
  // of, where loads are not (the empty asm keeps GCC from turning the reads
  // back into extractions).
  alignas(32) std::int32_t e[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(e), _mm256_slli_epi32(entry, 4));
  asm("" : "+m"(e));
  static_assert(sizeof(Rgba) == 16, "an entry is four floats");
  const char* bytes = reinterpret_cast<const char*>(table);
  Quads out;
  for (int j = 0; j < 4; ++j) {
    const __m256 low = _mm256_loadu_ps(reinterpret_cast<const float*>(bytes + e[j]));       // entries of sample j
    const __m256 high = _mm256_loadu_ps(reinterpret_cast<const float*>(bytes + e[j + 4]));  // entries of sample j + 4
    const __m256 front = _mm256_permute2f128_ps(low, high, 0x20);  // entry e of both
    const __m256 back = _mm256_permute2f128_ps(low, high, 0x31);   // entry e + 1 of both
    const __m256 w = _mm256_permutevar8x32_ps(weight, _mm256_setr_epi32(j, j, j, j, j + 4, j + 4, j + 4, j + 4));
    out.q[j] = _mm256_fmadd_ps(w, _mm256_sub_ps(back, front), front);
  }
  return out;
}

// Lanes whose mask is all ones keep their sample, the others become
// transparent (a non-finite scalar classifies as empty).
[[gnu::always_inline]] inline void keepQuads(Quads& s, __m256 mask) {
  for (int j = 0; j < 4; ++j)
    s.q[j] = _mm256_and_ps(s.q[j], _mm256_permutevar8x32_ps(
                                       mask, _mm256_setr_epi32(j, j, j, j, j + 4, j + 4, j + 4, j + 4)));
}

// f over b in each 128-bit half: f + (1 - f.a) b.
[[gnu::always_inline]] inline __m256 over2(__m256 f, __m256 b) {
  const __m256 t = _mm256_sub_ps(_mm256_set1_ps(1.0f), _mm256_permute_ps(f, 0xFF));
  return _mm256_fmadd_ps(t, b, f);
}

// s0 over s1 over ... over s7: ((s0 s1)(s2 s3))((s4 s5)(s6 s7)).
[[gnu::always_inline]] inline __m128 overQuads(const Quads& s) {
  const __m256 half = over2(over2(s.q[0], s.q[1]), over2(s.q[2], s.q[3]));  // [s0..s3 | s4..s7]
  const __m128 f = _mm256_castps256_ps128(half), b = _mm256_extractf128_ps(half, 1);
  const __m128 t = _mm_sub_ps(_mm_set1_ps(1.0f), _mm_permute_ps(f, 0xFF));
  return _mm_fmadd_ps(t, b, f);
}

// The accumulator (r, g, b, a in double) with c composited behind it.
[[gnu::always_inline]] inline __m256d addBehind4(__m256d acc, __m128 c) {
  const __m256d t = _mm256_sub_pd(_mm256_set1_pd(1.0), _mm256_permute4x64_pd(acc, 0xFF));
  return _mm256_fmadd_pd(t, _mm256_cvtps_pd(c), acc);
}

}  // namespace pvr::core::kernel

#endif
