// Loads and small arithmetic shared by the batched kernels (kernel_batch.h)
// and the batched lighting (shade_lanes.h): eight lanes, one sample each.
#pragma once

#if defined(__AVX2__) && defined(__FMA__)

#include <immintrin.h>

#include <cstdint>
#include <cstring>
#include <type_traits>

#include "kernel.h"

namespace pvr::core::kernel {

inline __m256i clampCells8(__m256 u, int lo, int hi) {
  return _mm256_min_epi32(_mm256_max_epi32(_mm256_cvttps_epi32(u), _mm256_set1_epi32(lo)),
                          _mm256_set1_epi32(hi));
}

inline __m256 lerp8(__m256 a, __m256 b, __m256 w) { return _mm256_fmadd_ps(w, _mm256_sub_ps(b, a), a); }

// A brick's voxel indexing as eight lanes, for voxelIndex8: kShifted, the
// strides' log2 (both strides powers of two, KernelParams::strideShift);
// else the strides. Set up once per run, outside the batch loop: the
// loop's stores through its 64-bit sample counter may alias p's 64-bit
// fields, so the compiler would not hoist the loads itself.
template <bool kShifted>
struct IndexLanes {
  __m256i base, byY, byZ;
  explicit IndexLanes(const KernelParams& p)
      : base(_mm256_set1_epi32(std::int32_t(p.base))),
        byY(_mm256_set1_epi32(std::int32_t(kShifted ? p.strideShift[0] : p.strideY))),
        byZ(_mm256_set1_epi32(std::int32_t(kShifted ? p.strideShift[1] : p.strideZ))) {}
};

// Voxel index i + j strideY + k strideZ + base of eight lanes' cells: by two
// shifts where kShifted, instead of two 32-bit multiplies, which lie on the
// batch's chain from its positions to its gathers (10 cycles and two uops
// each; peer scene: 3-5 % of a frame, bench/results/plain.txt, section 5).
template <bool kShifted>
[[gnu::always_inline]] inline __m256i voxelIndex8(const IndexLanes<kShifted>& by, __m256i i, __m256i j,
                                                  __m256i k) {
  const __m256i rows = kShifted ? _mm256_add_epi32(_mm256_sllv_epi32(j, by.byY), _mm256_sllv_epi32(k, by.byZ))
                                : _mm256_add_epi32(_mm256_mullo_epi32(j, by.byY), _mm256_mullo_epi32(k, by.byZ));
  return _mm256_add_epi32(_mm256_add_epi32(i, by.base), rows);
}

// Integer voxels packed two to a 32-bit lane (the first in the low bits)
// as floats: the first and the second of each lane.
template <typename T>
[[gnu::always_inline]] inline void splitPairs8(__m256i words, __m256& first, __m256& second) {
  constexpr int kBits = 8 * sizeof(T);
  if constexpr (std::is_signed_v<T>) {
    first = _mm256_cvtepi32_ps(_mm256_srai_epi32(_mm256_slli_epi32(words, 32 - kBits), 32 - kBits));
    second = _mm256_cvtepi32_ps(_mm256_srai_epi32(_mm256_slli_epi32(words, 32 - 2 * kBits), 32 - kBits));
  } else {
    const __m256i mask = _mm256_set1_epi32((1 << kBits) - 1);
    first = _mm256_cvtepi32_ps(_mm256_and_si256(words, mask));
    second = _mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(words, kBits), mask));
  }
}

// The 64 bits at b + index[j] of eight lanes, as two vectors of 32-bit
// halves in lane order: `low` gets each lane's first half, `high` its second.
template <typename T>
[[gnu::always_inline]] inline void load64x8(const T* b, const std::int32_t* index, __m256& low, __m256& high) {
  auto at = [b, index](int j) __attribute__((always_inline)) {
    long long w;
    std::memcpy(&w, b + index[j], sizeof w);
    return w;
  };
  const __m256 front = _mm256_castsi256_ps(_mm256_setr_epi64x(at(0), at(1), at(2), at(3)));  // lanes 0-3
  const __m256 back = _mm256_castsi256_ps(_mm256_setr_epi64x(at(4), at(5), at(6), at(7)));   // lanes 4-7
  // Halves in lane order 0 1 4 5 | 2 3 6 7; the 64-bit permute puts them in order.
  low = _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(_mm256_shuffle_ps(front, back, 0x88)), 0xD8));
  high = _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(_mm256_shuffle_ps(front, back, 0xDD)), 0xD8));
}

// How loadPairs8 fetches integer voxels' words: by the hardware gather, or
// by eight masked broadcast loads (AVX-512VL: a load and a blend each).
// Which is faster depends on the core, not on the code around it: on Intel
// (Emerald Rapids) an eight-lane gather takes 1.64 ns in L1 and the
// broadcasts made the peer scene's frame 7 % slower; AMD's Zen cores
// microcode their gathers (Zen 5: ~10 ns for one; the instructions after a
// batch's four gathers held about 40 % of the unshaded batch loop's
// profile) and the broadcasts are the faster (bench/results/plain.txt,
// section 6). -march=native tells us which core this build is for (GCC
// defines __znverN__ for every Zen it knows; GCC 12 takes a Zen 5 as znver3).
#if defined(__AVX512F__) && defined(__AVX512VL__) && \
    (defined(__znver1__) || defined(__znver2__) || defined(__znver3__) || defined(__znver4__) || defined(__znver5__))
inline constexpr bool kBroadcastPairs = true;
#else
inline constexpr bool kBroadcastPairs = false;
#endif

// The 32-bit words at b + index[j] (in T's units) of eight lanes, by the
// hardware gather.
template <typename T>
[[gnu::always_inline]] inline __m256i gatherWords8(const T* b, const std::int32_t* index) {
  return _mm256_i32gather_epi32(reinterpret_cast<const int*>(b),
                                _mm256_loadu_si256(reinterpret_cast<const __m256i*>(index)), sizeof(T));
}

#if defined(__AVX512F__) && defined(__AVX512VL__)
// gatherWords8() by eight loads, each broadcast into its lane under a mask.
template <typename T>
[[gnu::always_inline]] inline __m256i broadcastWords8(const T* b, const std::int32_t* index) {
  auto word = [b, index](int j) __attribute__((always_inline)) {
    std::int32_t w;
    std::memcpy(&w, b + index[j], sizeof w);
    return w;
  };
  __m256i words = _mm256_set1_epi32(word(0));
  for (int j = 1; j < 8; ++j) words = _mm256_mask_set1_epi32(words, __mmask8(1u << j), word(j));
  return words;
}
#endif

// The 32-bit words at b + index[j] of eight lanes, as loadPairs8 fetches
// integer voxels (kBroadcastPairs).
template <typename T>
[[gnu::always_inline]] inline __m256i loadWords8(const T* b, const std::int32_t* index) {
  if constexpr (kBroadcastPairs) return broadcastWords8(b, index);
  return gatherWords8(b, index);
}

// True when the bits at eight lanes' voxel indices (ClearCells) are all
// set. The byte indices go through memory: read back as scalars, not
// extracted on the shuffle port (classifyQuads).
[[gnu::always_inline]] inline bool allCellsClear8(const std::uint8_t* bits, __m256i index) {
  alignas(32) std::int32_t byte[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(byte), _mm256_srli_epi32(index, 3));
  asm("" : "+m"(byte));
  const __m256i bit = _mm256_srlv_epi32(loadWords8(bits, byte), _mm256_and_si256(index, _mm256_set1_epi32(7)));
  return _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_slli_epi32(bit, 31))) == 0xFF;
}

// Voxels index[j] + offset and index[j] + offset + 1 of eight lanes.
//
// Integer voxels: one 32-bit word per lane, which holds both neighbours
// (8-bit voxels: and two more, masked off by splitPairs8; the brick's
// storage ends with Brick::kPaddingBytes, so a word at its last voxel is
// readable), gathered or broadcast (kBroadcastPairs). Eight scalar loads,
// each moved into its lane by an insert, took more of the batch's shuffle
// port than the gather does on Intel (peer scene, with classifyQuads
// reading offsets from memory: 15 % less CPU time).
template <typename T>
[[gnu::always_inline]] inline void loadPairs8(const T* v, const std::int32_t* index, std::int64_t offset,
                                              __m256& lo, __m256& hi) {
  if constexpr (std::is_floating_point_v<T>) {
    load64x8(v + offset, index, lo, hi);
  } else {
    splitPairs8<T>(loadWords8(v + offset, index), lo, hi);
  }
}

// Voxels index[j] + offset + 0 .. 3 of eight lanes, one load per lane:
// q[n] gets the voxels at + n.
template <typename T>
[[gnu::always_inline]] inline void loadQuads8(const T* v, const std::int32_t* index, std::int64_t offset,
                                              __m256 q[4]) {
  const T* b = v + offset;
  if constexpr (std::is_floating_point_v<T>) {
    // Lanes j and j + 4 in one register, then a 4 x 4 transpose per half.
    __m256 m[4];
    for (int j = 0; j < 4; ++j)
      m[j] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(b + index[j])), _mm_loadu_ps(b + index[j + 4]), 1);
    const __m256 t0 = _mm256_unpacklo_ps(m[0], m[1]), t1 = _mm256_unpacklo_ps(m[2], m[3]);
    const __m256 t2 = _mm256_unpackhi_ps(m[0], m[1]), t3 = _mm256_unpackhi_ps(m[2], m[3]);
    q[0] = _mm256_shuffle_ps(t0, t1, 0x44);
    q[1] = _mm256_shuffle_ps(t0, t1, 0xEE);
    q[2] = _mm256_shuffle_ps(t2, t3, 0x44);
    q[3] = _mm256_shuffle_ps(t2, t3, 0xEE);
  } else if constexpr (sizeof(T) == 1) {
    auto word = [b, index](int j) __attribute__((always_inline)) {
      std::int32_t w;
      std::memcpy(&w, b + index[j], sizeof w);
      return w;
    };
    const __m256i words = _mm256_setr_epi32(word(0), word(1), word(2), word(3), word(4), word(5), word(6), word(7));
    const __m256i mask = _mm256_set1_epi32(0xFF);
    for (int n = 0; n < 4; ++n) {
      const __m256i byte = n == 3 ? _mm256_srli_epi32(words, 24) : _mm256_and_si256(_mm256_srli_epi32(words, 8 * n), mask);
      q[n] = _mm256_cvtepi32_ps(std::is_signed_v<T> ? _mm256_srai_epi32(_mm256_slli_epi32(byte, 24), 24) : byte);
    }
  } else {
    __m256 low, high;
    load64x8(b, index, low, high);
    splitPairs8<T>(_mm256_castps_si256(low), q[0], q[1]);
    splitPairs8<T>(_mm256_castps_si256(high), q[2], q[3]);
  }
}

}  // namespace pvr::core::kernel

#endif
