// Counting a brick's fine keys (value_histogram.h) row by row: the
// histogram half of the preprocessing pass (preprocess.h).
//
// One table increment per voxel is the cost (16-bit data: ~80 % of the
// pass on a 512^3 brick, perf), so the tables are what matter:
// - 32-bit counters, added to 64-bit totals before they could wrap: a
//   16-bit table is then 256 KiB where 64-bit ones were 512 KiB, and
//   data that spans the whole range (each voxel another cache line)
//   counts 1.6x as fast.
// - A block of 64 bytes of one value (air, flat regions) is one addition.
// - Neighbours that repeat a key would each wait for the last one's
//   increment; such blocks take two tables in turn (8-bit data four, all
//   the time: its tables are small). A block without a repeat among its
//   neighbours and next-but-one neighbours takes one table, so that a
//   wide-ranged row touches half the cache lines.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>
#include <vector>
#if defined(__AVX512BW__)
#include <immintrin.h>
#endif

#include "value_histogram.h"

namespace pvr::core {

// Whether the 64 bytes at `p` hold one integer value only: one compare
// with AVX-512, else an OR of differences, which compilers vectorise
// (a compare per element ORed as bool they do not: perf had that at one
// instruction chain per voxel).
template <typename T>
inline bool blockIsFlat(const T* p) {
  static_assert(std::is_integral_v<T>);
#if defined(__AVX512BW__)
  const __m512i v = _mm512_loadu_si512(p);
  if constexpr (sizeof(T) == 1) return _mm512_cmpneq_epi8_mask(v, _mm512_set1_epi8(char(p[0]))) == 0;
  else return _mm512_cmpneq_epi16_mask(v, _mm512_set1_epi16(short(p[0]))) == 0;
#else
  using U = std::make_unsigned_t<T>;
  U differ = 0;
  for (std::size_t k = 1; k < 64 / sizeof(T); ++k) differ |= U(U(p[k]) ^ U(p[0]));
  return differ == 0;
#endif
}

// Whether some 16-bit value of the 32 at `p` equals its neighbour or
// next-but-one neighbour (reads p[0] to p[33]). Without AVX-512: always
// yes, which counts the block on two tables, right for any block.
inline bool blockRepeats(const std::uint16_t* p) {
#if defined(__AVX512BW__)
  const __m512i v = _mm512_loadu_si512(p);
  return (_mm512_cmpeq_epi16_mask(v, _mm512_loadu_si512(p + 1)) |
          _mm512_cmpeq_epi16_mask(v, _mm512_loadu_si512(p + 2))) != 0;
#else
  (void)p;
  return true;
#endif
}

template <typename T>
class FineCounter {
 public:
  // Tables a repeating block is counted into: four for 8-bit data (4 KB in
  // all; eight measured no faster), two for the others (65536 keys each).
  static constexpr std::size_t kTables = sizeof(T) == 1 ? 4 : 2;
  static constexpr std::size_t kKeys = kFineKeys<T>;
  static constexpr std::uint64_t kMaxPending = std::numeric_limits<std::uint32_t>::max();

  // `flushEvery`: voxels counted into the 32-bit tables before they go to
  // the 64-bit totals (at most kMaxPending; tests pass less).
  explicit FineCounter(std::uint64_t flushEvery = kMaxPending)
      : tables_(kTables * kKeys, 0), flushEvery_(std::clamp<std::uint64_t>(flushEvery, 1, kMaxPending)) {}

  // Counts the fine keys of the row's n values (finite ones for float).
  void countRow(const T* r, std::size_t n) {
    while (n > 0) {
      if (pending_ == flushEvery_) flush();
      const std::size_t piece = std::size_t(std::min<std::uint64_t>(n, flushEvery_ - pending_));
      countPiece(r, piece);
      pending_ += piece;
      r += piece;
      n -= piece;
    }
  }

  // Adds the counts to `out` (sized kKeys).
  void addTo(std::vector<std::uint64_t>& out) const {
    for (std::size_t k = 0; k < tables_.size(); ++k) out[k % kKeys] += tables_[k];
    for (std::size_t k = 0; k < totals_.size(); ++k) out[k] += totals_[k];
  }

 private:
  void flush() {
    totals_.resize(kKeys, 0);
    for (std::size_t k = 0; k < tables_.size(); ++k) totals_[k % kKeys] += tables_[k];
    std::fill(tables_.begin(), tables_.end(), 0);
    pending_ = 0;
  }

  void countPiece(const T* __restrict r, std::size_t n) {
    std::uint32_t* __restrict t = tables_.data();
    std::uint32_t* __restrict a = t;
    std::uint32_t* __restrict b = t + kKeys;
    std::size_t i = 0;
    if constexpr (!std::is_floating_point_v<T>) {
      constexpr std::size_t kBlock = 64 / sizeof(T);
      for (; i + kBlock <= n; i += kBlock) {
        if (blockIsFlat(r + i)) {
          a[fineKey(r[i])] += kBlock;
          continue;
        }
        if constexpr (sizeof(T) == 1) {
          for (std::size_t k = 0; k < kBlock; k += 8) {
            std::uint64_t w;
            std::memcpy(&w, r + i + k, 8);  // little or big endian: each byte is counted once either way
            for (std::size_t byte = 0; byte < 8; ++byte) ++t[byte % kTables * kKeys + ((w >> (8 * byte)) & 255)];
          }
        } else {
          const T* p = r + i;
          if (i + kBlock + 2 <= n && !blockRepeats(reinterpret_cast<const std::uint16_t*>(p))) {
            for (std::size_t k = 0; k < kBlock; ++k) ++a[fineKey(p[k])];
          } else {
            for (std::size_t k = 0; k < kBlock; k += 2) {
              ++a[fineKey(p[k])];
              ++b[fineKey(p[k + 1])];
            }
          }
        }
      }
    }
    for (; i + 1 < n; i += 2) {
      if constexpr (std::is_floating_point_v<T>) {
        if ((r[i] - r[i]) == T(0)) ++a[fineKey(r[i])];
        if ((r[i + 1] - r[i + 1]) == T(0)) ++b[fineKey(r[i + 1])];
      } else {
        ++a[fineKey(r[i])];
        ++b[fineKey(r[i + 1])];
      }
    }
    if (i < n && (r[i] - r[i]) == T(0)) ++a[fineKey(r[i])];
  }

  std::vector<std::uint32_t> tables_;  // kTables x kKeys
  std::vector<std::uint64_t> totals_;  // kKeys, sized at the first flush
  std::uint64_t pending_ = 0;          // voxels in tables_ since the last flush
  std::uint64_t flushEvery_;
};

}  // namespace pvr::core
