// Loads and small arithmetic shared by the batched kernels (kernel_batch.h)
// and the batched lighting (shade_lanes.h): eight lanes, one sample each.
#pragma once

#if defined(__AVX2__) && defined(__FMA__)

#include <immintrin.h>

#include <cstdint>
#include <cstring>
#include <type_traits>

namespace pvr::core::kernel {

inline __m256i clampCells8(__m256 u, int lo, int hi) {
  return _mm256_min_epi32(_mm256_max_epi32(_mm256_cvttps_epi32(u), _mm256_set1_epi32(lo)),
                          _mm256_set1_epi32(hi));
}

inline __m256 lerp8(__m256 a, __m256 b, __m256 w) { return _mm256_fmadd_ps(w, _mm256_sub_ps(b, a), a); }

// Voxels index[j] + offset and index[j] + offset + 1 of eight lanes.
template <typename T>
[[gnu::always_inline]] inline void loadPairs8(const T* v, const std::int32_t* index, std::int64_t offset,
                                              __m256& lo, __m256& hi) {
  const T* b = v + offset;
  if constexpr (std::is_floating_point_v<T>) {
    lo = _mm256_setr_ps(b[index[0]], b[index[1]], b[index[2]], b[index[3]], b[index[4]], b[index[5]],
                        b[index[6]], b[index[7]]);
    hi = _mm256_setr_ps(b[index[0] + 1], b[index[1] + 1], b[index[2] + 1], b[index[3] + 1],
                        b[index[4] + 1], b[index[5] + 1], b[index[6] + 1], b[index[7] + 1]);
  } else {
    // One load of twice the scalar's width holds both neighbours.
    using Pair = std::conditional_t<sizeof(T) == 1, std::uint16_t, std::uint32_t>;
    auto pair = [b](std::int32_t at) __attribute__((always_inline)) {
      Pair w;
      std::memcpy(&w, b + at, sizeof w);
      return std::int32_t(w);
    };
    const __m256i words = _mm256_setr_epi32(pair(index[0]), pair(index[1]), pair(index[2]), pair(index[3]),
                                            pair(index[4]), pair(index[5]), pair(index[6]), pair(index[7]));
    constexpr int kBits = 8 * sizeof(T);
    if constexpr (std::is_signed_v<T>) {
      lo = _mm256_cvtepi32_ps(_mm256_srai_epi32(_mm256_slli_epi32(words, 32 - kBits), 32 - kBits));
      hi = _mm256_cvtepi32_ps(_mm256_srai_epi32(_mm256_slli_epi32(words, 32 - 2 * kBits), 32 - kBits));
    } else {
      const __m256i mask = _mm256_set1_epi32((1 << kBits) - 1);
      lo = _mm256_cvtepi32_ps(_mm256_and_si256(words, mask));
      hi = _mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(words, kBits), mask));
    }
  }
}

}  // namespace pvr::core::kernel

#endif
