// Preprocessing (preprocess.h, macrocells.h, content.h): what the fast
// passes compute equals what a brute-force loop over the definition
// computes, for every scalar type, on odd-sized bricks with ghosts at the
// grid's edges and in its middle, single-threaded and on a pool alike; and
// the raw reader's fused pass equals reading first and preprocessing after.
#include <catch2/catch.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "brick.h"
#include "decompose/content.h"
#include "io/volume_io.h"
#include "preprocess.h"
#include "raycast/leap_distance.h"
#include "raycast/macrocells.h"
#include "raycast/raycaster.h"
#include "test_files.h"
#include "thread_pool.h"

namespace pvr::core {
namespace {

constexpr ScalarType kTypes[] = {ScalarType::kUInt8, ScalarType::kUInt16, ScalarType::kInt16,
                                 ScalarType::kFloat32};

GridGeometry gridOf(IVec3 dims) {
  GridGeometry g;
  g.dims = dims;
  g.spacing = {1, 1, 1};
  return g;
}

// Owned boxes of an odd-sized grid: the whole, one at the near corner, one
// in the middle starting off the macrocell lattice, one at the far corner.
const IVec3 kDims{37, 29, 23};
const NodeBox kOwnedBoxes[] = {
    {{0, 0, 0}, {36, 28, 22}},
    {{0, 0, 0}, {17, 13, 9}},
    {{5, 6, 7}, {22, 19, 15}},
    {{18, 13, 10}, {36, 28, 22}},
};

// Random voxels over the type's whole range; float gets NaN and +-Inf
// sprinkled in, and one 6^3 corner block all NaN (its macrocell is empty).
Brick randomBrick(ScalarType type, const NodeBox& owned, int ghost, std::uint32_t seed) {
  const GridGeometry grid = gridOf(kDims);
  const NodeBox stored = owned.grown(ghost).intersect(grid.allNodes());
  Brick b(grid, type, owned, stored);
  std::mt19937 rng(seed);
  dispatchScalar(type, [&](auto tag) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
    T* v = b.as<T>();
    for (std::int64_t z = stored.lo.z; z <= stored.hi.z; ++z)
      for (std::int64_t y = stored.lo.y; y <= stored.hi.y; ++y)
        for (std::int64_t x = stored.lo.x; x <= stored.hi.x; ++x) {
          T& out = v[b.linearIndex({x, y, z})];
          if constexpr (std::is_floating_point_v<T>) {
            const std::uint32_t r = rng();
            out = std::uniform_real_distribution<float>(-1e3f, 1e3f)(rng);
            if (r % 17 == 0) out = std::numeric_limits<float>::quiet_NaN();
            if (r % 29 == 0) out = (r & 1) ? std::numeric_limits<float>::infinity()
                                           : -std::numeric_limits<float>::infinity();
            if (x < stored.lo.x + 6 && y < stored.lo.y + 6 && z < stored.lo.z + 6)
              out = std::numeric_limits<float>::quiet_NaN();
          } else {
            out = T(std::uniform_int_distribution<int>(std::numeric_limits<T>::lowest(),
                                                       std::numeric_limits<T>::max())(rng));
          }
        }
  });
  return b;
}

// Reference bounds: macrocell m holds the finite stored nodes in
// [4m, 4m + 4] on each axis.
void checkBoundsAgainstBruteForce(const Brick& b, const MacrocellBounds& bounds) {
  const MacrocellLayout l = MacrocellLayout::forOwned(b.owned());
  REQUIRE(bounds.layout() == l);
  REQUIRE(bounds.type() == b.type());
  CHECK(bounds.byteSize() == 2 * l.size() * scalarSize(b.type()));
  const NodeBox& st = b.stored();
  std::size_t mismatches = 0;
  for (std::int64_t k = 0; k < l.count.z; ++k)
    for (std::int64_t j = 0; j < l.count.y; ++j)
      for (std::int64_t i = 0; i < l.count.x; ++i) {
        const IVec3 m{l.first.x + i, l.first.y + j, l.first.z + k};
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (std::int64_t z = std::max(st.lo.z, 4 * m.z); z <= std::min(st.hi.z, 4 * m.z + 4); ++z)
          for (std::int64_t y = std::max(st.lo.y, 4 * m.y); y <= std::min(st.hi.y, 4 * m.y + 4); ++y)
            for (std::int64_t x = std::max(st.lo.x, 4 * m.x); x <= std::min(st.hi.x, 4 * m.x + 4); ++x) {
              const double v = b.valueAt({x, y, z});
              if (!std::isfinite(v)) continue;
              lo = std::min(lo, v);
              hi = std::max(hi, v);
            }
        const std::size_t idx = std::size_t((k * l.count.y + j) * l.count.x + i);
        if (lo > hi) {  // no finite node: the macrocell stays empty (min > max)
          if (!(bounds.minAt(idx) > bounds.maxAt(idx))) ++mismatches;
        } else if (bounds.minAt(idx) != lo || bounds.maxAt(idx) != hi) {
          ++mismatches;
        }
      }
  CHECK(mismatches == 0);
}

ValueRange bruteForceRange(const Brick& b) {
  ValueRange r{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(), 0};
  const NodeBox& st = b.stored();
  for (std::int64_t z = st.lo.z; z <= st.hi.z; ++z)
    for (std::int64_t y = st.lo.y; y <= st.hi.y; ++y)
      for (std::int64_t x = st.lo.x; x <= st.hi.x; ++x) {
        const double v = b.valueAt({x, y, z});
        if (!std::isfinite(v)) {
          ++r.nonFinite;
          continue;
        }
        r.min = std::min(r.min, v);
        r.max = std::max(r.max, v);
      }
  if (r.min > r.max) r.min = r.max = 0;
  return r;
}

void checkRange(const ValueRange& got, const ValueRange& want) {
  CHECK(got.min == want.min);
  CHECK(got.max == want.max);
  CHECK(got.nonFinite == want.nonFinite);
}

bool sameBounds(const MacrocellBounds& a, const MacrocellBounds& b) {
  if (!(a.layout() == b.layout()) || a.type() != b.type()) return false;
  for (std::size_t i = 0; i < a.layout().size(); ++i) {
    // Compare bit patterns so that empty float macrocells (inf, -inf) match too.
    const double x[2] = {a.minAt(i), a.maxAt(i)}, y[2] = {b.minAt(i), b.maxAt(i)};
    if (std::memcmp(x, y, sizeof x) != 0) return false;
  }
  return true;
}

// Reference chessboard distance: min(255, max(|dx|, |dy|, |dz|) to the nearest 0).
std::vector<std::uint8_t> bruteForceDistance(const std::vector<std::uint8_t>& visible, IVec3 n) {
  std::vector<std::uint8_t> out(visible.size(), 255);
  for (std::int64_t z = 0; z < n.z; ++z)
    for (std::int64_t y = 0; y < n.y; ++y)
      for (std::int64_t x = 0; x < n.x; ++x) {
        std::int64_t best = 255;
        for (std::int64_t qz = 0; qz < n.z; ++qz)
          for (std::int64_t qy = 0; qy < n.y; ++qy)
            for (std::int64_t qx = 0; qx < n.x; ++qx)
              if (visible[std::size_t((qz * n.y + qy) * n.x + qx)])
                best = std::min(best, std::max({std::abs(qx - x), std::abs(qy - y), std::abs(qz - z)}));
        out[std::size_t((z * n.y + y) * n.x + x)] = std::uint8_t(best);
      }
  return out;
}

std::vector<std::uint8_t> fastDistance(const std::vector<std::uint8_t>& visible, IVec3 n, ThreadPool* pool) {
  std::vector<std::uint8_t> d(visible.size());
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = visible[i] ? 0 : 255;
  chessboardDistance(d.data(), n, pool);
  return d;
}

// A transfer function that shows values in a window of the type's range.
TransferTable windowTable(ScalarType type) {
  TransferFunctionSpec tf;
  const double lo = type == ScalarType::kUInt8 ? 0 : type == ScalarType::kUInt16 ? 0
                  : type == ScalarType::kInt16 ? -32768 : -1000;
  const double hi = type == ScalarType::kUInt8 ? 255 : type == ScalarType::kUInt16 ? 65535
                  : type == ScalarType::kInt16 ? 32767 : 1000;
  const double w = hi - lo;
  tf.points = {{lo, 0, 0, 0, 0}, {lo + 0.3 * w, 1, 1, 1, 0}, {lo + 0.4 * w, 1, 0, 0, 0.5},
               {lo + 0.5 * w, 1, 1, 1, 0}, {lo + 0.8 * w, 1, 1, 1, 0}, {hi, 0, 1, 0, 0.2}};
  tf.unitDistance = 1;
  return TransferTable(tf, 0.5);
}

// Shows every value from 70% of the type's range up: one interval.
TransferTable upperTable(ScalarType type) {
  TransferFunctionSpec tf;
  const double lo = type == ScalarType::kInt16 ? -32768 : type == ScalarType::kFloat32 ? -1000 : 0;
  const double hi = type == ScalarType::kUInt8 ? 255 : type == ScalarType::kUInt16 ? 65535
                  : type == ScalarType::kInt16 ? 32767 : 1000;
  tf.points = {{lo, 0, 0, 0, 0}, {lo + 0.7 * (hi - lo), 0, 0, 0, 0}, {hi, 1, 1, 1, 0.5}};
  tf.unitDistance = 1;
  return TransferTable(tf, 0.5);
}

// Reference content counts: the owned nodes (half-open, closed at the
// grid's far edge) whose finite value the table shows, per block.
ContentGrid bruteForceContent(const Brick& b, const TransferTable& table, IVec3 blockCells) {
  ContentGrid c = makeContentGrid(b.grid(), blockCells);
  const NodeBox& own = b.owned();
  for (std::int64_t z = own.lo.z; z <= own.hi.z; ++z)
    for (std::int64_t y = own.lo.y; y <= own.hi.y; ++y)
      for (std::int64_t x = own.lo.x; x <= own.hi.x; ++x) {
        const IVec3 n{x, y, z};
        bool counted = true;
        for (int a = 0; a < 3; ++a) counted &= n[a] < own.hi[a] || own.hi[a] == b.grid().dims[a] - 1;
        const double v = b.valueAt(n);
        if (!counted || !std::isfinite(v) || !table.anyVisible(v, v)) continue;
        IVec3 blk;
        for (int a = 0; a < 3; ++a) blk[a] = std::min(n[a] / blockCells[a], c.blocks[a] - 1);
        ++c.counts[std::size_t((blk.z * c.blocks.y + blk.y) * c.blocks.x + blk.x)];
      }
  return c;
}

}  // namespace

TEST_CASE("macrocell bounds and value range equal brute force for every scalar type", "[preprocess]") {
  ThreadPool pool(2);
  std::uint32_t seed = 1;
  for (ScalarType type : kTypes)
    for (const NodeBox& owned : kOwnedBoxes)
      for (int ghost : {0, 1, 3}) {
        CAPTURE(scalarName(type), toString(owned), ghost);
        Brick b = randomBrick(type, owned, ghost, seed++);
        const ValueRange want = bruteForceRange(b);

        // One pass, single-threaded, through the brick.
        b.updateValueRange();
        const std::byte* voxels = std::as_const(b).bytes();  // reading keeps the bounds
        REQUIRE(b.macrocellBounds());
        checkBoundsAgainstBruteForce(b, *b.macrocellBounds());
        checkRange(b.valueRange(), want);

        // The same on a pool of two.
        const Preprocessed threaded = preprocessVoxels(type, b.owned(), b.stored(), voxels, &pool);
        CHECK(sameBounds(*threaded.bounds, *b.macrocellBounds()));
        checkRange(threaded.range, want);

        // Streamed one slab at a time, last slab first.
        SlabPreprocessor streamed(type, b.owned(), b.stored());
        const std::size_t slabBytes = std::size_t(b.stored().extent(0) * b.stored().extent(1)) * scalarSize(type);
        for (std::int64_t z = b.stored().hi.z; z >= b.stored().lo.z; --z)
          streamed.add(voxels + std::size_t(z - b.stored().lo.z) * slabBytes, z, z);
        const Preprocessed s = streamed.finish();
        CHECK(sameBounds(*s.bounds, *threaded.bounds));
        checkRange(s.range, want);
      }
}

TEST_CASE("a float brick without a finite voxel has the range [0, 0] and only empty macrocells", "[preprocess]") {
  const GridGeometry grid = gridOf({9, 6, 5});
  Brick b(grid, ScalarType::kFloat32, grid.allNodes(), grid.allNodes());
  std::fill_n(b.as<float>(), grid.allNodes().nodeCount(), std::numeric_limits<float>::quiet_NaN());
  b.updateValueRange();
  CHECK(b.valueRange().min == 0);
  CHECK(b.valueRange().max == 0);
  CHECK(b.valueRange().nonFinite == std::uint64_t(grid.allNodes().nodeCount()));
  const MacrocellBounds& bounds = *b.macrocellBounds();
  for (std::size_t i = 0; i < bounds.layout().size(); ++i) CHECK(bounds.minAt(i) > bounds.maxAt(i));
}

TEST_CASE("writing a brick's voxels drops its macrocell bounds and updateValueRange brings them back", "[preprocess]") {
  Brick b = randomBrick(ScalarType::kUInt8, kOwnedBoxes[2], 1, 7);
  b.updateValueRange();
  REQUIRE(b.macrocellBounds());
  b.as<std::uint8_t>()[0] = 3;
  CHECK_FALSE(b.macrocellBounds());
  b.updateValueRange();
  REQUIRE(b.macrocellBounds());
  checkBoundsAgainstBruteForce(b, *b.macrocellBounds());
}

TEST_CASE("the separable distance field equals brute-force chessboard distance", "[preprocess]") {
  ThreadPool pool(2);
  std::mt19937 rng(11);
  const IVec3 shapes[] = {{13, 9, 21}, {1, 1, 40}, {40, 1, 1}, {7, 12, 1}, {16, 16, 16}};
  for (const IVec3 n : shapes)
    for (double density : {0.0, 0.002, 0.02, 0.3, 1.0}) {
      CAPTURE(n.x, n.y, n.z, density);
      std::vector<std::uint8_t> visible(std::size_t(n.product()));
      std::bernoulli_distribution coin(density);
      for (auto& v : visible) v = coin(rng);
      const auto want = bruteForceDistance(visible, n);
      CHECK(fastDistance(visible, n, nullptr) == want);
      CHECK(fastDistance(visible, n, &pool) == want);
    }
}

// A leap distance (leap_distance.h) against the exact chessboard distance:
// zero exactly where visible, exact below kLeapNear, beyond it never more
// than the truth and less by at most the coarse blocks' slack.
static void checkLeapDistance(const std::uint8_t* got, const std::vector<std::uint8_t>& exact) {
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < exact.size(); ++i) {
    const int want = exact[i], d = got[i];
    if (!leapDistanceFits(d, want) && wrong++ < 5) FAIL_CHECK("macrocell " << i << ": leap distance " << d << ", exact " << want);
  }
  CHECK(wrong == 0);
}

TEST_CASE("the leap distance is exact near what is visible and a close lower bound far from it", "[preprocess]") {
  ThreadPool pool(2);
  std::mt19937 rng(5);
  // Several coarse blocks per axis, partial blocks at the ends, and a run
  // longer than the 255 cap.
  const IVec3 shapes[] = {{70, 45, 38}, {1, 1, 300}, {300, 2, 3}, {33, 1, 80}, {16, 16, 16}};
  for (const IVec3 n : shapes)
    for (double density : {0.0, 0.00005, 0.0005, 0.01, 0.3, 1.0}) {
      CAPTURE(n.x, n.y, n.z, density);
      std::vector<std::uint8_t> visible(std::size_t(n.product()));
      std::bernoulli_distribution coin(density);
      for (auto& v : visible) v = coin(rng);
      if (density == 0.00005) visible[0] = 1;  // one speck in a corner
      const auto exact = fastDistance(visible, n, nullptr);
      for (ThreadPool* p : {static_cast<ThreadPool*>(nullptr), &pool}) {
        std::vector<std::uint8_t> d(visible.size());
        for (std::size_t i = 0; i < d.size(); ++i) d[i] = visible[i] ? 0 : 255;
        leapDistance(d.data(), n, p);
        checkLeapDistance(d.data(), exact);
      }
    }
}

// The forward distance by its definition: the least over visible q in the
// octant ahead of m (q_a - m_a of the octant's sign on every axis, or 0)
// of the largest |q_a - m_a|, capped at 255.
static std::vector<std::uint8_t> bruteForwardDistance(const std::vector<std::uint8_t>& visible, IVec3 n, int octant) {
  std::vector<IVec3> shown;
  for (std::int64_t z = 0; z < n.z; ++z)
    for (std::int64_t y = 0; y < n.y; ++y)
      for (std::int64_t x = 0; x < n.x; ++x)
        if (visible[std::size_t((z * n.y + y) * n.x + x)]) shown.push_back({x, y, z});
  std::vector<std::uint8_t> out(visible.size(), 255);
  for (std::int64_t z = 0; z < n.z; ++z)
    for (std::int64_t y = 0; y < n.y; ++y)
      for (std::int64_t x = 0; x < n.x; ++x) {
        const IVec3 m{x, y, z};
        std::int64_t best = 255;
        for (const IVec3& q : shown) {
          std::int64_t far = 0;
          bool ahead = true;
          for (int a = 0; a < 3; ++a) {
            const std::int64_t t = (octant >> a & 1) ? m[a] - q[a] : q[a] - m[a];
            ahead = ahead && t >= 0;
            far = std::max(far, t);
          }
          if (ahead) best = std::min(best, far);
        }
        out[std::size_t((z * n.y + y) * n.x + x)] = std::uint8_t(best);
      }
  return out;
}

// forwardLeapDistance (leap_distance.h) for each of the eight octants: zero
// exactly where visible, the exact forward distance below kLeapNear (a
// window one macrocell too long, or reaching backwards, fails here), and
// beyond it at least kLeapNear and never more than the truth.
TEST_CASE("the forward leap distance of each octant is exact near what is visible ahead", "[preprocess]") {
  ThreadPool pool(2);
  std::mt19937 rng(23);
  const IVec3 shapes[] = {{23, 17, 29}, {1, 1, 60}, {60, 2, 1}, {40, 33, 1}};
  for (const IVec3 n : shapes)
    for (double density : {0.0, 0.0005, 0.005, 0.05, 0.4, 1.0}) {
      std::vector<std::uint8_t> visible(std::size_t(n.product()));
      std::bernoulli_distribution coin(density);
      for (auto& v : visible) v = coin(rng);
      if (density == 0.0005) visible[visible.size() / 2] = 1;  // one speck in the middle
      for (int octant = 0; octant < 8; ++octant) {
        CAPTURE(n.x, n.y, n.z, density, octant);
        const auto exact = bruteForwardDistance(visible, n, octant);
        for (ThreadPool* p : {static_cast<ThreadPool*>(nullptr), &pool}) {
          std::vector<std::uint8_t> d(visible.size());
          for (std::size_t i = 0; i < d.size(); ++i) d[i] = visible[i] ? 0 : 255;
          forwardLeapDistance(d.data(), n, octant, p);
          std::size_t wrong = 0;
          for (std::size_t i = 0; i < exact.size(); ++i) {
            const int want = exact[i], got = d[i];
            const bool fits = want < kLeapNear ? got == want : got >= kLeapNear && got <= want;
            if (!fits && wrong++ < 5) FAIL_CHECK("macrocell " << i << ": forward distance " << got << ", exact " << want);
          }
          CHECK(wrong == 0);
        }
      }
    }
}

TEST_CASE("the distance field caps at 255 along a long empty line", "[preprocess]") {
  // One visible macrocell at x = 0 of 300: distances 0, 1, ..., 254, 255, 255, ...
  const IVec3 n{300, 2, 3};
  std::vector<std::uint8_t> visible(std::size_t(n.product()), 0);
  visible[0] = 1;
  const auto d = fastDistance(visible, n, nullptr);
  CHECK(d == bruteForceDistance(visible, n));
  CHECK(d[254] == 254);
  CHECK(d[299] == 255);
  CHECK(d[std::size_t(n.x * n.y * 2 + 10)] == 10);  // z = 2: max(|dz| = 2, |dx| = 10)
}

TEST_CASE("classification marks a macrocell visible exactly when its bounds are", "[preprocess]") {
  ThreadPool pool(2);
  for (ScalarType type : kTypes) {
    CAPTURE(scalarName(type));
    Brick b = randomBrick(type, kOwnedBoxes[2], 1, 5);
    b.updateValueRange();
    const TransferTable table = windowTable(type);
    MacrocellGrid single(b), threaded(b, &pool);
    single.classify(table, true);
    threaded.classify(table, true, &pool);
    const MacrocellBounds& bounds = single.bounds();
    const IVec3 n = single.count();
    std::vector<std::uint8_t> visible(std::size_t(n.product()));
    for (std::size_t i = 0; i < visible.size(); ++i)
      visible[i] = bounds.minAt(i) <= bounds.maxAt(i) && table.anyVisible(bounds.minAt(i), bounds.maxAt(i));
    const auto exact = bruteForceDistance(visible, n);
    checkLeapDistance(single.distance(), exact);
    CHECK(std::equal(single.distance(), single.distance() + exact.size(), threaded.distance()));
    // The grid shares the brick's bounds instead of copying them.
    CHECK(&single.bounds() == b.macrocellBounds().get());
  }
}

TEST_CASE("fine counts of flat runs, runs broken by one voxel and changing values equal a count of every voxel", "[preprocess]") {
  // Rows of 150 nodes: blocks of equal values are counted at once, a block
  // with one other value voxel by voxel, and the rest of a row after the
  // last whole block one by one.
  const GridGeometry grid = gridOf({150, 6, 4});
  for (ScalarType type : kTypes) {
    CAPTURE(scalarName(type));
    Brick b(grid, type, grid.allNodes(), grid.allNodes());
    std::mt19937 rng(7);
    dispatchScalar(type, [&](auto tag) {
      using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
      T* v = b.as<T>();
      for (std::int64_t z = 0; z < 4; ++z)
        for (std::int64_t y = 0; y < 6; ++y)
          for (std::int64_t x = 0; x < 150; ++x) {
            T value = T(y + 3);                                        // flat
            if (y % 3 == 1 && x == 70) value = T(100);                 // one voxel breaks a block
            if (y % 3 == 2) value = T(std::uniform_int_distribution<int>(0, 120)(rng));  // changing
            v[b.linearIndex({x, y, z})] = value;
          }
      b.updateValueRange();
      std::vector<std::uint64_t> expected(fineKeyCount(type), 0);
      const NodeBox counted = countedBox(b.owned(), grid);
      for (std::int64_t z = counted.lo.z; z <= counted.hi.z; ++z)
        for (std::int64_t y = counted.lo.y; y <= counted.hi.y; ++y)
          for (std::int64_t x = counted.lo.x; x <= counted.hi.x; ++x) ++expected[fineKey(v[b.linearIndex({x, y, z})])];
      REQUIRE(b.fineHistogram());
      CHECK(b.fineHistogram()->counts == expected);
    });
  }
}

TEST_CASE("rows wide enough for the vector loops: bounds, range and fine counts equal brute force", "[preprocess]") {
  // Rows of 263 nodes run the sliding-window and 64-byte loops through
  // their vector bodies and remainders; boxes off the macrocell lattice
  // clip a macrocell at either x end. Values: flat runs that cross block
  // edges, runs broken by one voxel, random values (float: NaN and Inf).
  const GridGeometry grid = gridOf({263, 11, 9});
  const NodeBox owned[] = {grid.allNodes(), {{5, 2, 1}, {201, 9, 7}}, {{130, 0, 4}, {262, 10, 8}}};
  std::uint32_t seed = 40;
  for (ScalarType type : kTypes)
    for (const NodeBox& own : owned)
      for (int ghost : {0, 1, 3}) {
        CAPTURE(scalarName(type), toString(own), ghost);
        Brick b(grid, type, own, own.grown(ghost).intersect(grid.allNodes()));
        const NodeBox& st = b.stored();
        std::mt19937 rng(seed++);
        dispatchScalar(type, [&](auto tag) {
          using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
          const double lo = double(std::numeric_limits<T>::lowest()), hi = double(std::numeric_limits<T>::max());
          auto any = [&] {
            if constexpr (std::is_floating_point_v<T>) return T(std::uniform_real_distribution<float>(-1e3f, 1e3f)(rng));
            else return T(std::uniform_int_distribution<long>(long(lo), long(hi))(rng));
          };
          T* v = b.as<T>();
          for (std::int64_t z = st.lo.z; z <= st.hi.z; ++z)
            for (std::int64_t y = st.lo.y; y <= st.hi.y; ++y) {
              T run = any();
              for (std::int64_t x = st.lo.x; x <= st.hi.x; ++x) {
                if (x % 71 == 0) run = any();                   // flat runs of 71
                T value = (y + z) % 3 == 0 ? any() : run;       // or changing throughout
                if ((y + z) % 3 == 1 && x % 97 == 5) value = any();  // one voxel breaks a run
                if constexpr (std::is_floating_point_v<T>) {
                  if (x % 53 == 7) value = std::numeric_limits<T>::quiet_NaN();
                  if (x % 89 == 3) value = (y & 1) ? std::numeric_limits<T>::infinity() : -std::numeric_limits<T>::infinity();
                }
                v[b.linearIndex({x, y, z})] = value;
              }
            }
          b.updateValueRange();
          const std::byte* voxels = std::as_const(b).bytes();
          REQUIRE(b.macrocellBounds());
          checkBoundsAgainstBruteForce(b, *b.macrocellBounds());
          checkRange(b.valueRange(), bruteForceRange(b));

          std::vector<std::uint64_t> expected(fineKeyCount(type), 0);
          const NodeBox counted = countedBox(own, grid);
          for (std::int64_t z = counted.lo.z; z <= counted.hi.z; ++z)
            for (std::int64_t y = counted.lo.y; y <= counted.hi.y; ++y)
              for (std::int64_t x = counted.lo.x; x <= counted.hi.x; ++x) {
                const T value = v[b.linearIndex({x, y, z})];
                if (std::isfinite(double(value))) ++expected[fineKey(value)];
              }
          REQUIRE(b.fineHistogram());
          CHECK(b.fineHistogram()->counts == expected);

          // Streamed slab by slab, as the raw reader does: the same.
          SlabPreprocessor streamed(type, own, st, &counted);
          const std::size_t slabBytes = std::size_t(st.extent(0) * st.extent(1)) * sizeof(T);
          for (std::int64_t z = st.lo.z; z <= st.hi.z; ++z)
            streamed.add(voxels + std::size_t(z - st.lo.z) * slabBytes, z, z);
          const Preprocessed s = streamed.finish();
          CHECK(sameBounds(*s.bounds, *b.macrocellBounds()));
          checkRange(s.range, b.valueRange());
          CHECK(s.histogram->counts == expected);
        });
      }
}

TEST_CASE("content counts equal brute force for every scalar type, single-threaded and on a pool", "[preprocess]") {
  ThreadPool pool(2);
  std::uint32_t seed = 100;
  TransferFunctionSpec invisible;
  invisible.points = {{0, 1, 1, 1, 0}, {1, 1, 1, 1, 0}};
  invisible.unitDistance = 1;
  for (ScalarType type : kTypes)
    for (const NodeBox& owned : kOwnedBoxes)
      for (IVec3 blockCells : {IVec3{8, 8, 8}, IVec3{3, 5, 7}}) {
        CAPTURE(scalarName(type), toString(owned), blockCells.x, blockCells.y);
        const Brick b = randomBrick(type, owned, 1, seed++);
        // Two shown intervals, one, and none at all.
        const TransferTable tables[] = {windowTable(type), upperTable(type), TransferTable(invisible, 0.5)};
        for (const TransferTable& table : tables) {
          const ContentGrid want = bruteForceContent(b, table, blockCells);
          CHECK(countContent(b, table, blockCells).counts == want.counts);
          CHECK(countContent(b, table, blockCells, &pool).counts == want.counts);
        }
        CHECK(totalContent(bruteForceContent(b, tables[0], blockCells)) > 0);
        CHECK(totalContent(bruteForceContent(b, tables[1], blockCells)) > 0);
        CHECK(totalContent(bruteForceContent(b, tables[2], blockCells)) == 0);
      }
}

TEST_CASE("the raw reader's fused preprocessing equals reading, then preprocessing", "[preprocess][io]") {
  const std::string dir = test::scratchDir("preprocess_fused");
  for (ScalarType type : kTypes)
    for (bool bigEndian : {false, true}) {
      if (type == ScalarType::kUInt8 && bigEndian) continue;
      CAPTURE(scalarName(type), bigEndian);
      // The whole volume, written as raw + JSON in the chosen byte order.
      Brick whole = randomBrick(type, kOwnedBoxes[0], 0, 40 + unsigned(type));
      const std::string stem = std::string(scalarName(type)) + (bigEndian ? "_be" : "_le");
      std::vector<std::byte> raw(whole.bytes(), whole.bytes() + whole.byteSize());
      const std::size_t size = scalarSize(type);
      if (bigEndian != (std::endian::native == std::endian::big))
        for (std::size_t i = 0; i < raw.size(); i += size) std::reverse(&raw[i], &raw[i] + size);
      {
        std::ofstream out(dir + "/" + stem + ".raw", std::ios::binary);
        out.write(reinterpret_cast<const char*>(raw.data()), std::streamsize(raw.size()));
      }
      test::writeText(dir + "/" + stem + ".json",
                      "{\"dims\": [" + std::to_string(kDims.x) + ", " + std::to_string(kDims.y) + ", " +
                          std::to_string(kDims.z) + "], \"dtype\": \"" + std::string(scalarName(type)) +
                          "\", \"spacing\": [1, 1, 1], \"endian\": \"" + (bigEndian ? "big" : "little") + "\"}");
      const auto source = openVolumeFile(dir + "/" + stem + ".json");
      REQUIRE(source->canReadPartially());

      // Bricks at the grid's edges and in its middle, whole rows and not.
      for (const NodeBox& owned : kOwnedBoxes)
        for (int ghost : {0, 2}) {
          CAPTURE(toString(owned), ghost);
          const NodeBox stored = owned.grown(ghost).intersect(whole.grid().allNodes());
          const Brick fused = source->readBox(owned, stored);
          const Brick twoPass = cropBrick(whole, owned, ghost);
          REQUIRE(fused.byteSize() == twoPass.byteSize());
          CHECK(std::memcmp(fused.bytes(), twoPass.bytes(), fused.byteSize()) == 0);
          REQUIRE(fused.macrocellBounds());
          REQUIRE(twoPass.macrocellBounds());
          CHECK(sameBounds(*fused.macrocellBounds(), *twoPass.macrocellBounds()));
          checkRange(fused.valueRange(), twoPass.valueRange());
          REQUIRE(fused.fineHistogram());
          REQUIRE(twoPass.fineHistogram());
          CHECK(fused.fineHistogram()->counts == twoPass.fineHistogram()->counts);
          CHECK(fused.loadTimes().read > 0);
          CHECK(fused.loadTimes().preprocess > 0);

          // Told to count nothing (pvr-node --batch): the same bounds and
          // range, no histogram.
          source->setFineCounts(false);
          const Brick uncounted = source->readBox(owned, stored);
          source->setFineCounts(true);
          CHECK_FALSE(uncounted.fineHistogram());
          REQUIRE(uncounted.macrocellBounds());
          CHECK(sameBounds(*uncounted.macrocellBounds(), *twoPass.macrocellBounds()));
          checkRange(uncounted.valueRange(), twoPass.valueRange());
        }
    }
}

TEST_CASE("the raw reader reads long rows one call each and short rows in spans, the same voxels", "[preprocess][io]") {
  // float32 rows of 4400 nodes: a brick 4300 wide has rows of 17200 bytes,
  // above the reader's 16 KiB span threshold; one 300 wide stays below it.
  const std::string dir = test::scratchDir("preprocess_rows");
  const GridGeometry grid = gridOf({4400, 5, 4});
  Brick whole(grid, ScalarType::kFloat32, grid.allNodes(), grid.allNodes());
  float* v = whole.as<float>();
  for (std::int64_t i = 0; i < grid.allNodes().nodeCount(); ++i) v[i] = float(i % 9973) * 0.5f;
  whole.updateValueRange();
  const auto source = openVolumeFile(writeRawJsonVolume(whole, dir, "rows", "long rows"));
  for (const NodeBox owned : {NodeBox{{50, 1, 1}, {4349, 3, 2}}, NodeBox{{1000, 0, 0}, {1299, 4, 3}}}) {
    CAPTURE(toString(owned));
    const Brick fused = source->readBox(owned, owned.grown(1).intersect(grid.allNodes()));
    const Brick twoPass = cropBrick(whole, owned, 1);
    REQUIRE(fused.byteSize() == twoPass.byteSize());
    CHECK(std::memcmp(fused.bytes(), twoPass.bytes(), fused.byteSize()) == 0);
    CHECK(sameBounds(*fused.macrocellBounds(), *twoPass.macrocellBounds()));
    checkRange(fused.valueRange(), twoPass.valueRange());
  }
}

TEST_CASE("a brick of whole slabs keeps the raw file's pages, equal to a copy, until it is written", "[preprocess][io]") {
  // 64 x 64 x 8 uint16 nodes: 64 KiB, whole pages, so the last slab ends
  // where the file ends and the padding past it is not the file's.
  const std::string dir = test::scratchDir("preprocess_lent");
  const GridGeometry grid = gridOf({64, 64, 8});
  Brick whole(grid, ScalarType::kUInt16, grid.allNodes(), grid.allNodes());
  std::uint16_t* v = whole.as<std::uint16_t>();
  for (std::int64_t i = 0; i < grid.allNodes().nodeCount(); ++i) v[i] = std::uint16_t(i * 7919 % 65521);
  whole.updateValueRange();
  const auto source = openVolumeFile(writeRawJsonVolume(whole, dir, "slabs", "whole slabs"));
  for (const NodeBox owned : {NodeBox{{0, 0, 0}, {63, 63, 3}}, NodeBox{{0, 0, 4}, {63, 63, 7}}}) {
    CAPTURE(toString(owned));
    const Brick lent = source->readBox(owned, owned.grown(1).intersect(grid.allNodes()));
    const Brick copied = cropBrick(whole, owned, 1);
    CHECK(lent.lent());
    REQUIRE(lent.byteSize() == copied.byteSize());
    CHECK(std::memcmp(lent.bytes(), copied.bytes(), lent.byteSize()) == 0);
    CHECK(sameBounds(*lent.macrocellBounds(), *copied.macrocellBounds()));
    checkRange(lent.valueRange(), copied.valueRange());
    // The kernels may load a word at the last voxel: the padding is there.
    for (std::size_t i = 0; i < Brick::kPaddingBytes; ++i) CHECK(lent.bytes()[lent.byteSize() + i] == std::byte{0});

    // Writing gives the brick storage of its own; the file and a brick
    // still lent stay as they were.
    Brick written = lent;
    written.as<std::uint16_t>()[0] = 1;
    CHECK_FALSE(written.lent());
    CHECK(written.as<std::uint16_t>()[0] == 1);
    CHECK(std::memcmp(written.bytes() + 2, copied.bytes() + 2, lent.byteSize() - 2) == 0);
    CHECK(lent.lent());
    CHECK(std::memcmp(lent.bytes(), copied.bytes(), lent.byteSize()) == 0);
  }
  // Rows that are not whole, or bytes to swap, are copied.
  const Brick half = source->readBox({{0, 0, 0}, {31, 63, 7}}, {{0, 0, 0}, {32, 63, 7}});
  CHECK_FALSE(half.lent());
  test::writeText(dir + "/slabs_be.json", "{\"dims\": [64, 64, 8], \"dtype\": \"uint16\", \"raw_file\": \"slabs.raw\", "
                                          "\"spacing\": [1, 1, 1], \"endian\": \"big\"}");
  CHECK_FALSE(openVolumeFile(dir + "/slabs_be.json")->readBox(grid.allNodes(), grid.allNodes()).lent());
}

TEST_CASE("a lent brick lies at an address that agrees with its file offset modulo 2 MiB", "[preprocess][io]") {
  // So the page cache's 2 MiB folios map whole (one entry each, not 512;
  // byte_stream.cpp). 64 x 64 x 40 uint8 nodes, bricks starting at several
  // slabs, none of them on a 2 MiB boundary of the file.
  const std::string dir = test::scratchDir("preprocess_lent_aligned");
  const GridGeometry grid = gridOf({64, 64, 40});
  Brick whole(grid, ScalarType::kUInt8, grid.allNodes(), grid.allNodes());
  std::uint8_t* v = whole.as<std::uint8_t>();
  for (std::int64_t i = 0; i < grid.allNodes().nodeCount(); ++i) v[i] = std::uint8_t(i * 31 % 251);
  whole.updateValueRange();
  const auto source = openVolumeFile(writeRawJsonVolume(whole, dir, "slabs", "whole slabs"));
  constexpr std::uintptr_t kTwoMiB = std::uintptr_t(2) << 20;
  for (const std::int64_t z0 : {1, 5, 13, 30}) {
    CAPTURE(z0);
    const NodeBox owned{{0, 0, z0}, {63, 63, 39}};
    const NodeBox stored = owned.grown(1).intersect(grid.allNodes());
    const Brick lent = source->readBox(owned, stored);
    REQUIRE(lent.lent());
    const std::uintptr_t fileOffset = std::uintptr_t(stored.lo.z) * 64 * 64;
    CHECK((reinterpret_cast<std::uintptr_t>(lent.bytes()) - fileOffset) % kTwoMiB == 0);
    const Brick copied = cropBrick(whole, owned, 1);
    REQUIRE(lent.byteSize() == copied.byteSize());
    CHECK(std::memcmp(lent.bytes(), copied.bytes(), lent.byteSize()) == 0);
    for (std::size_t i = 0; i < Brick::kPaddingBytes; ++i) CHECK(lent.bytes()[lent.byteSize() + i] == std::byte{0});
  }
}

TEST_CASE("a brick renders the same with the bounds it carries as with bounds the renderer computes", "[preprocess]") {
  const GridGeometry grid = gridOf({33, 30, 27});
  Brick carried(grid, ScalarType::kUInt16, grid.allNodes(), grid.allNodes());
  std::uint16_t* v = carried.as<std::uint16_t>();
  for (std::int64_t z = 0; z < 27; ++z)
    for (std::int64_t y = 0; y < 30; ++y)
      for (std::int64_t x = 0; x < 33; ++x)
        v[carried.linearIndex({x, y, z})] =
            std::uint16_t(60000.0 * std::exp(-0.01 * double((x - 14) * (x - 14) + (y - 15) * (y - 15) + (z - 10) * (z - 10))));
  carried.updateValueRange();
  Brick computed = carried;
  computed.bytes();  // drops the copy's bounds
  REQUIRE(carried.macrocellBounds());
  REQUIRE_FALSE(computed.macrocellBounds());

  TransferFunctionSpec tf;
  tf.points = {{0, 0, 0, 0, 0}, {20000, 0, 0, 0, 0}, {40000, 1, 0.5, 0.2, 0.3}, {65535, 1, 1, 1, 0.8}};
  tf.unitDistance = 1;
  RenderOptions options;
  options.step = 0.5;
  CameraSpec cs;
  cs.projection = Projection::kPerspective;
  cs.eye = {60, -40, 50};
  cs.lookAt = {16, 15, 13};
  cs.up = {0, 0, 1};
  cs.fovYDeg = 40;
  cs.automatic = false;
  const Camera camera(cs, 48, 40);
  ThreadPool pool(2);
  BrickRenderer a(carried), b(computed, &pool);
  // Only the renderer that had to compute bounds reports time spent on them.
  CHECK(a.preprocessSeconds() == 0);
  CHECK(b.preprocessSeconds() > 0);
  CHECK(&a.macrocells().bounds() == carried.macrocellBounds().get());
  a.classify(tf, options);
  b.classify(tf, options, &pool);
  const Image ia = a.render(camera, options, pool), ib = b.render(camera, options, pool);
  REQUIRE(ia.rect() == ib.rect());
  REQUIRE_FALSE(ia.rect().empty());
  bool same = true;
  for (int y = ia.rect().y0; y < ia.rect().y1; ++y)
    for (int x = ia.rect().x0; x < ia.rect().x1; ++x)
      same &= std::memcmp(&ia.at(x, y), &ib.at(x, y), sizeof(ia.at(x, y))) == 0;
  CHECK(same);
}

}  // namespace pvr::core
