// Fine counts (fine_counts.h, preprocess.h): whatever path a block of a row takes (one
// addition for a flat block, one table for a block without neighbouring
// repeats, two or four tables in turn, the row's tail) and however often
// the 32-bit tables go to the 64-bit totals, the counts equal a count of
// every voxel; and counting them alone (countFineKeys) gives the counts of
// the pass that also computes the bounds.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <type_traits>
#include <vector>

#include "brick.h"
#include "fine_counts.h"
#include "preprocess.h"
#include "thread_pool.h"

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

TEST_CASE("counting the fine keys alone equals a count of every voxel, single-threaded and on a pool", "[preprocess]") {
  // Odd grid, owned boxes at a corner, off the macrocell lattice and at the
  // far end, ghost layers or none; int16 over its whole range (negative
  // values too), float with NaN.
  GridGeometry grid;
  grid.dims = {67, 13, 11};
  grid.spacing = {1, 1, 1};
  const NodeBox owned[] = {grid.allNodes(), {{0, 0, 0}, {33, 6, 5}}, {{5, 3, 2}, {50, 11, 9}}, {{34, 6, 5}, {66, 12, 10}}};
  ThreadPool pool(2);
  std::uint32_t seed = 3;
  for (ScalarType type : {ScalarType::kUInt8, ScalarType::kUInt16, ScalarType::kInt16, ScalarType::kFloat32})
    for (const NodeBox& own : owned)
      for (int ghost : {0, 2}) {
        CAPTURE(scalarName(type), toString(own), ghost);
        Brick b(grid, type, own, own.grown(ghost).intersect(grid.allNodes()));
        const NodeBox counted = countedBox(own, grid);
        std::vector<std::uint64_t> expected(fineKeyCount(type), 0);
        std::mt19937 rng(seed++);
        dispatchScalar(type, [&](auto tag) {
          using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
          T* v = b.as<T>();
          const std::size_t n = std::size_t(b.stored().nodeCount());
          for (std::size_t i = 0; i < n; ++i) {
            if constexpr (std::is_floating_point_v<T>)
              v[i] = i % 17 == 0 ? std::numeric_limits<T>::quiet_NaN() : T(std::uniform_real_distribution<float>(-5, 5)(rng));
            else  // runs of one value now and then, so flat blocks and repeats occur
              v[i] = i % 97 < 40 ? T(-7) : T(std::uniform_int_distribution<long>(long(std::numeric_limits<T>::lowest()),
                                                                                 long(std::numeric_limits<T>::max()))(rng));
          }
          for (std::int64_t z = counted.lo.z; z <= counted.hi.z; ++z)
            for (std::int64_t y = counted.lo.y; y <= counted.hi.y; ++y)
              for (std::int64_t x = counted.lo.x; x <= counted.hi.x; ++x) {
                const T value = v[b.linearIndex({x, y, z})];
                if (std::isfinite(double(value))) ++expected[fineKey(value)];
              }
        });
        const std::byte* voxels = std::as_const(b).bytes();
        CHECK(countFineKeys(type, b.stored(), voxels, counted)->counts == expected);
        CHECK(countFineKeys(type, b.stored(), voxels, counted, &pool)->counts == expected);
        // The brick's own count, after a reader that counted nothing.
        b.countFineHistogram(&pool);
        REQUIRE(b.fineHistogram());
        CHECK(b.fineHistogram()->counts == expected);
      }
}

}  // namespace pvr::core
