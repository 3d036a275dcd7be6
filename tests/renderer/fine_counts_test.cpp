// Fine counts (fine_counts.h): whatever path a block of a row takes (one
// addition for a flat block, one table for a block without neighbouring
// repeats, two or four tables in turn, the row's tail) and however often
// the 32-bit tables go to the 64-bit totals, the counts equal a count of
// every voxel.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <type_traits>
#include <vector>

#include "fine_counts.h"

namespace pvr::core {
namespace {

// Rows of every kind a block meets, for lengths around the block and
// look-ahead edges (32 16-bit values plus the two the repeat test reads).
template <typename T>
std::vector<std::vector<T>> rowsOfEveryKind() {
  std::mt19937 rng(11);
  auto any = [&] {
    if constexpr (std::is_floating_point_v<T>) return T(std::uniform_real_distribution<float>(-1e4f, 1e4f)(rng));
    else
      return T(std::uniform_int_distribution<long>(long(std::numeric_limits<T>::lowest()),
                                                    long(std::numeric_limits<T>::max()))(rng));
  };
  std::vector<std::vector<T>> rows;
  for (std::size_t n : {1, 2, 31, 32, 33, 34, 35, 63, 64, 66, 67, 100, 263}) {
    std::vector<T> wide(n), flat(n, any()), pairs(n), alternating(n), broken(n, T(-3)), noisy(n);
    const T a = any(), b = any();
    for (std::size_t x = 0; x < n; ++x) {
      wide[x] = any();                                       // no repeats: one table
      pairs[x] = x % 7 == 3 ? wide[x - 1] : wide[x];          // a repeat of a neighbour now and then
      alternating[x] = x % 2 ? a : b;                         // repeats two apart only
      if (x == n / 2) broken[x] = T(5);                       // a flat block broken by one voxel
      noisy[x] = T(std::uniform_int_distribution<int>(-4, 4)(rng));  // few keys, negative ones too
    }
    if constexpr (std::is_floating_point_v<T>) {
      wide[n / 3] = std::numeric_limits<T>::quiet_NaN();     // float counts finite values only
      noisy[n - 1] = std::numeric_limits<T>::infinity();
    }
    for (auto* r : {&wide, &flat, &pairs, &alternating, &broken, &noisy}) rows.push_back(*r);
  }
  return rows;
}

template <typename T>
void checkCounts(std::uint64_t flushEvery) {
  FineCounter<T> counter(flushEvery);
  std::vector<std::uint64_t> expected(FineCounter<T>::kKeys, 0);
  // Each row twice: the flushes fall on other voxels the second time.
  for (int pass = 0; pass < 2; ++pass)
    for (const std::vector<T>& row : rowsOfEveryKind<T>()) {
      counter.countRow(row.data(), row.size());
      for (T v : row)
        if (std::isfinite(double(v))) ++expected[fineKey(v)];
    }
  std::vector<std::uint64_t> counts(FineCounter<T>::kKeys, 0);
  counter.addTo(counts);
  CHECK(counts == expected);
}

}  // namespace

TEST_CASE("fine counts of rows of every kind equal a count of every voxel, whenever the tables are flushed", "[preprocess]") {
  for (std::uint64_t flushEvery : {std::uint64_t(1), std::uint64_t(7), std::uint64_t(33), std::uint64_t(100),
                                   FineCounter<std::uint16_t>::kMaxPending}) {
    CAPTURE(flushEvery);
    checkCounts<std::uint8_t>(flushEvery);
    checkCounts<std::uint16_t>(flushEvery);
    checkCounts<std::int16_t>(flushEvery);
    checkCounts<float>(flushEvery);
  }
}

TEST_CASE("a 16-bit key counted 2^32 + 2 times keeps every count past the 32-bit tables", "[preprocess]") {
  // One flat block adds 32 at once: 2^27 of them reach 2^32, which a
  // 32-bit table would wrap to 0.
  FineCounter<std::uint16_t> counter;
  const std::vector<std::uint16_t> row(std::size_t(1) << 16, std::uint16_t(40000));
  for (int i = 0; i < (1 << 16); ++i) counter.countRow(row.data(), row.size());
  const std::uint16_t two[] = {7, 40000};
  counter.countRow(two, 2);
  counter.countRow(two + 1, 1);
  std::vector<std::uint64_t> counts(FineCounter<std::uint16_t>::kKeys, 0);
  counter.addTo(counts);
  CHECK(counts[40000] == (std::uint64_t(1) << 32) + 2);
  CHECK(counts[7] == 1);
}

}  // namespace pvr::core
