// The batched plain kernel (renderer/raycast/kernel_batch.h): eight samples
// reconstructed, classified and composited together (kernel_batch_over.h),
// whole batches of transparent samples skipped, early termination tested
// per batch; against the one-at-a-time loop and closed forms.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

#include "raycast/cast_ray.h"
#include "raycast/kernel_setup.h"
#include "raycast/macrocells.h"
#include "batch_runs.h"
#include "kernel_fixture.h"
#include "reference.h"
#include "transfer.h"

#ifdef PVR_HAVE_BATCH_KERNEL

namespace pvr::core {
namespace {


using Setup = KernelFixture;
using test::alongX;
using test::batchedRun;
using test::difference;
using test::Run;
using test::scalarRun;

}  // namespace

// Identity: the batch's tree of "over"s in float, then one update of the
// double accumulator, equals compositing sample after sample in double up
// to float rounding of the batch (a few ulp of each batch's colour), 1e-5
// at most over rays of ~100 samples through a dense, sharply classified
// volume, with transparent stretches (clear ends of the transfer function)
// and, in float32, non-finite voxels that classify as empty. Every ray of a
// view, unshaded and shaded (the specular power from the table and by
// steps, specular_power.h), uint8 and float32.
TEST_CASE("the batched plain kernel equals the scalar kernel", "[raycast]") {
  // 32: strides of powers of two, whose voxel indices the batch takes by
  // shifts (KernelParams::strideShift); 40: by multiplies.
  const std::int64_t n = GENERATE(40, 32);
  const GridGeometry grid = cubeGrid(n);
  auto field = [](Vec3 q) { return 0.5 + 0.45 * std::sin(q.x * 0.31) * std::cos(q.y * 0.23 + q.z * 0.17); };
  const TransferFunctionSpec tf = transfer({{0.0, 0, 0, 0, 0},
                                            {0.3, 0.2, 0.5, 1.0, 0},
                                            {0.5, 1.0, 0.8, 0.3, 0.5},
                                            {0.52, 0.2, 0.9, 0.3, 0.05},
                                            {0.8, 0.9, 0.9, 0.9, 0.3},
                                            {0.85, 0, 0, 0, 0},
                                            {1.0, 0, 0, 0, 0}});
  const TransferFunctionSpec tf8 = [&] {
    TransferFunctionSpec t = tf;
    for (TransferPoint& point : t.points) point.scalar *= 255;
    return t;
  }();
  const Brick floats = makeVolume(grid, ScalarType::kFloat32, [&](Vec3 q) {
    // A few non-finite voxels inside visible stretches.
    if (int(q.x) % 7 == 3 && int(q.y) % 5 == 2) return std::numeric_limits<double>::quiet_NaN();
    if (int(q.x) % 11 == 5 && int(q.z) % 3 == 1) return std::numeric_limits<double>::infinity();
    return field(q);
  });
  const Brick bytes = makeVolume(grid, ScalarType::kUInt8, [&](Vec3 q) { return 255 * field(q); });
  const Camera camera = test::obliqueView(grid, 24);
  for (const Brick* volume : {&floats, &bytes}) {
    const bool uint8 = volume->type() == ScalarType::kUInt8;
    for (int mode : {0, 1, 2}) {  // unshaded; shaded, the power from the table; shaded, by steps
      const bool shaded = mode > 0;
      const RenderOptions o = makeOptions(0.45, false, shaded);
      Setup s(*volume, uint8 ? tf8 : tf, o);
      REQUIRE(s.p.indices32);
      REQUIRE((s.p.strideShift[0] == 5 && s.p.strideShift[1] == 10) == (n == 32));
      REQUIRE(s.p.clearBelow > 0);
      REQUIRE(s.p.clearAbove < float(TransferTable::kEntries - 1));
      double worst = 0;
      int rays = 0;
      for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 24; ++x) {
          const RaySetup ray = raySetup(camera.ray(x, y), grid, o.step, normalize(Vec3{0.2, 0.4, -1}));
          std::int64_t first = 0, last = 0;
          if (!kernel::sampleRange(s.p, ray, first, last) || last - first < 20) continue;
          auto both = [&](auto tag) {
            using V = std::remove_pointer_t<decltype(tag)>;
            if (mode == 0) return std::pair{scalarRun<V, false>(s.p, ray, first, last), batchedRun<V, false>(s.p, ray, first, last)};
            if (mode == 1) return std::pair{scalarRun<V, true>(s.p, ray, first, last), batchedRun<V, true>(s.p, ray, first, last)};
            return std::pair{scalarRun<V, true, kernel::kPowerBits>(s.p, ray, first, last),
                             batchedRun<V, true, kernel::kPowerBits>(s.p, ray, first, last)};
          };
          const auto [a, b] = uint8 ? both(static_cast<std::uint8_t*>(nullptr)) : both(static_cast<float*>(nullptr));
          CHECK(a.samples == b.samples);
          CHECK(std::isfinite(b.acc.r + b.acc.g + b.acc.b + b.acc.a));
          worst = std::max(worst, difference(a.acc, b.acc));
          ++rays;
        }
      INFO((uint8 ? "uint8" : "float32") << (shaded ? " shaded" : " unshaded") << " mode " << mode << ": " << rays
                                         << " rays, max difference " << worst);
      CHECK(rays > 100);
      CHECK(worst < 1e-5);
    }
  }
}

// Identity, as above, for the integer types whose corner pairs come by
// one 32-bit gather per lane (batch_loads.h, loadPairs8): uint16 and int16
// (a gather of the wrong scale or sign extension differs at once), and
// uint8 along the grid's last row, whose last pair ends at the storage's
// last voxel: its 32-bit word reaches two bytes into Brick::kPaddingBytes,
// which the pair must not take in.
TEST_CASE("the batched plain kernel equals the scalar kernel on gathered integer voxels", "[raycast]") {
  const std::int64_t n = GENERATE(40, 32);  // indices by multiplies, by shifts
  const GridGeometry grid = cubeGrid(n);
  auto field = [](Vec3 q) { return 0.5 + 0.45 * std::sin(q.x * 0.31) * std::cos(q.y * 0.23 + q.z * 0.17); };
  auto scaled = [](double scale, double offset) {
    TransferFunctionSpec t = transfer({{0.0, 0, 0, 0, 0},
                                       {0.3, 0.2, 0.5, 1.0, 0},
                                       {0.5, 1.0, 0.8, 0.3, 0.5},
                                       {0.8, 0.9, 0.9, 0.9, 0.3},
                                       {1.0, 0.3, 0.2, 0.1, 0.2}});
    for (TransferPoint& point : t.points) point.scalar = point.scalar * scale + offset;
    return t;
  };
  using Case = test::ScaledType;
  const Camera camera = test::obliqueView(grid, 24);
  const RenderOptions o = makeOptions(0.45, false, false);
  for (const Case& k : {Case{ScalarType::kUInt16, 60000, 0}, Case{ScalarType::kInt16, 60000, -30000},
                        Case{ScalarType::kUInt8, 255, 0}}) {
    const Brick volume = makeVolume(grid, k.type, [&](Vec3 q) { return field(q) * k.scale + k.offset; });
    Setup s(volume, scaled(k.scale, k.offset), o);
    REQUIRE(s.p.indices32);
    REQUIRE((s.p.strideShift[0] >= 0) == (n == 32));
    auto compare = [&](const RaySetup& ray, std::int64_t first, std::int64_t last) {
      return dispatchScalar(k.type, [&](auto tag) {
        using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
        const Run a = scalarRun<T, false>(s.p, ray, first, last);
        const Run b = batchedRun<T, false>(s.p, ray, first, last);
        CHECK(a.samples == b.samples);
        CHECK(a.acc.a > 0);
        return difference(a.acc, b.acc);
      });
    };
    double worst = 0;
    int rays = 0;
    if (k.type == ScalarType::kUInt8) {
      // Along the last row: the batches' far corners are the storage's last voxels.
      const RaySetup ray = alongX(double(n - 1), double(n - 1), 0.45);
      std::int64_t first = 0, last = 0;
      REQUIRE(kernel::sampleRange(s.p, ray, first, last));
      first = last - (last - first) / 8 * 8;  // whole batches up to sample last - 1,
      REQUIRE(double(last - 1) * 0.45 >= double(n - 2));  // which lies in the last cell
      worst = compare(ray, first, last);
      rays = 1;
    } else {
      for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 24; ++x) {
          const RaySetup ray = raySetup(camera.ray(x, y), grid, o.step, normalize(Vec3{0.2, 0.4, -1}));
          std::int64_t first = 0, last = 0;
          if (!kernel::sampleRange(s.p, ray, first, last) || last - first < 20) continue;
          worst = std::max(worst, compare(ray, first, last));
          ++rays;
        }
      CHECK(rays > 100);
    }
    INFO(int(k.type) << ": " << rays << " rays, max difference " << worst);
    CHECK(worst < 1e-5);
  }
}

// Identity: N samples of one medium, each of opacity a and premultiplied
// colour c, composite to opacity 1 - (1 - a)^N and colour c / a times that.
// 10^4 samples of opacity 0.0014 reach 0.9999992; a float accumulator
// stalls at ~0.99998 (kernel::Accumulator), a float product of
// transmittances drifts by ~1e-6 per 10^3 samples. Batched, the result is
// within 1e-8 of the closed form.
TEST_CASE("a long ray of faint samples reaches its exact opacity batched", "[raycast]") {
  const GridGeometry grid = cubeGrid(24);
  const Brick volume = makeVolume(grid, ScalarType::kFloat32, [](Vec3) { return 0.5; });
  const double step = 0.0022;  // over 10^4 samples across the grid
  // Opacity per unit length chosen so that one step's opacity is 0.0014.
  const double unitOpacity = 1 - std::pow(1 - 0.0014, 1 / step);
  const TransferFunctionSpec tf = transfer({{0.0, 0.6, 0.3, 0.1, unitOpacity}, {1.0, 0.6, 0.3, 0.1, unitOpacity}});
  Setup s(volume, tf, makeOptions(step));
  const RaySetup ray = alongX(11.3, 12.6, step);
  std::int64_t first = 0, last = 0;
  REQUIRE(kernel::sampleRange(s.p, ray, first, last));
  const Rgba one = kernel::classify1D(s.p, 0.5f);
  REQUIRE(std::abs(one.a - 0.0014) < 1e-6);
  const std::int64_t n = 10000;
  REQUIRE(last - first + 1 >= n);
  const Run b = batchedRun<float, false>(s.p, ray, first, first + n);
  REQUIRE(b.samples == std::uint64_t(n));
  const double opacity = -std::expm1(double(n) * std::log1p(-double(one.a)));
  INFO("opacity " << b.acc.a << ", exact " << opacity);
  CHECK(opacity > 0.999999);
  CHECK(std::abs(b.acc.a - opacity) < 1e-8);
  CHECK(std::abs(b.acc.r - double(one.r) / double(one.a) * opacity) < 1e-7);
  CHECK(std::abs(b.acc.b - double(one.b) / double(one.a) * opacity) < 1e-7);
}

// Where the transfer function is transparent below 0.3 and above 0.7, the
// table's clear ends are exactly the coordinates whose two entries are
// zero; a ray along a ramp from 0 to 1 crosses both ends, with batches
// entirely in them (skipped), batches across their edges and batches in
// between, and composites what the scalar loop composites. A transfer
// function visible at the very ends of its table has no clear ends; an
// empty one is clear everywhere and leaves the ray transparent.
TEST_CASE("batches of transparent samples are skipped and add nothing", "[raycast]") {
  const GridGeometry grid = cubeGrid(33);
  const Brick ramp = makeVolume(grid, ScalarType::kFloat32, [](Vec3 q) { return q.x / 32; });
  const TransferFunctionSpec middle = transfer(
      {{0.0, 0, 0, 0, 0}, {0.3, 0.5, 0.5, 0.5, 0}, {0.5, 1.0, 0.2, 0.1, 0.4}, {0.7, 0.1, 0.5, 0.9, 0}, {1.0, 0, 0, 0, 0}});
  const RenderOptions o = makeOptions(0.37);
  {
    Setup s(ramp, middle, o);
    const Rgba* e = s.table.entries();
    auto zero = [](const Rgba& c) { return c.r == 0 && c.g == 0 && c.b == 0 && c.a == 0; };
    const int below = int(s.p.clearBelow), above = int(s.p.clearAbove);
    // Entries 0 .. below are zero and entry below + 1 is not; likewise above.
    CHECK(float(below) == s.p.clearBelow);
    for (int i = 0; i <= below; ++i) REQUIRE(zero(e[i]));
    CHECK_FALSE(zero(e[below + 1]));
    for (int i = above; i < TransferTable::kEntries; ++i) REQUIRE(zero(e[i]));
    CHECK_FALSE(zero(e[above - 1]));
    for (double y : {3.0, 10.5, 20.25}) {
      const RaySetup ray = alongX(y, 16.5, o.step);
      std::int64_t first = 0, last = 0;
      REQUIRE(kernel::sampleRange(s.p, ray, first, last));
      // Start at several offsets so that batch edges fall everywhere.
      for (std::int64_t shift = 0; shift < 8; ++shift) {
        const Run a = scalarRun<float, false>(s.p, ray, first + shift, last);
        const Run b = batchedRun<float, false>(s.p, ray, first + shift, last);
        CHECK(a.samples == b.samples);
        CHECK(a.acc.a > 0.1);
        CHECK(difference(a.acc, b.acc) < 1e-6);
      }
    }
  }
  {
    const TransferFunctionSpec ends = transfer({{0.0, 1, 1, 1, 0.5}, {0.5, 0, 0, 0, 0}, {1.0, 1, 0, 0, 0.5}});
    Setup s(ramp, ends, o);
    CHECK(s.p.clearBelow < 0);
    CHECK(s.p.clearAbove == std::numeric_limits<float>::max());
    const RaySetup ray = alongX(7.5, 8.5, o.step);
    std::int64_t first = 0, last = 0;
    REQUIRE(kernel::sampleRange(s.p, ray, first, last));
    const Run a = scalarRun<float, false>(s.p, ray, first, last);
    const Run b = batchedRun<float, false>(s.p, ray, first, last);
    CHECK(a.acc.a > 0.5);
    CHECK(difference(a.acc, b.acc) < 1e-6);
  }
  {
    const TransferFunctionSpec empty = transfer({{0.0, 1, 1, 1, 0}, {1.0, 1, 0, 0, 0}});
    Setup s(ramp, empty, o);
    const RaySetup ray = alongX(7.5, 8.5, o.step);
    std::int64_t first = 0, last = 0;
    REQUIRE(kernel::sampleRange(s.p, ray, first, last));
    const Run b = batchedRun<float, false>(s.p, ray, first, last);
    CHECK(b.samples == std::uint64_t(last - first));
    CHECK(b.acc.a == 0);
    CHECK(b.acc.r == 0);
  }
}

// Early termination is tested after each batch: the ray stops at the end
// of the batch in which its opacity passed the threshold, with what the
// scalar loop composites over exactly those samples.
TEST_CASE("early termination inside a batch stops at the batch's end", "[raycast]") {
  const GridGeometry grid = cubeGrid(33);
  const Brick ramp = makeVolume(grid, ScalarType::kUInt8, [](Vec3 q) { return 255 * q.x / 32; });
  const TransferFunctionSpec rising = transfer({{0.0, 0.2, 0.4, 0.8, 0.0}, {255.0, 0.9, 0.5, 0.1, 0.9}});
  RenderOptions o = makeOptions(0.29);
  o.earlyTermination = 0.95;
  Setup s(ramp, rising, o);
  const RaySetup ray = alongX(16.5, 16.5, o.step);
  std::int64_t first = 0, last = 0;
  REQUIRE(kernel::sampleRange(s.p, ray, first, last));
  for (std::int64_t shift = 0; shift < 8; ++shift) {
    const Run scalar = scalarRun<std::uint8_t, false>(s.p, ray, first + shift, last);
    REQUIRE(scalar.terminated);
    const Run batched = batchedRun<std::uint8_t, false>(s.p, ray, first + shift, last);
    REQUIRE(batched.terminated);
    // The batch holding sample stop - 1 is the last one taken.
    const std::int64_t batchEnd = first + shift + (std::int64_t(scalar.samples) + 7) / 8 * 8;
    INFO("shift " << shift << ": scalar stopped after " << scalar.samples << " samples");
    CHECK(batched.stoppedAt == batchEnd);
    CHECK(batched.samples == std::uint64_t(batchEnd - first - shift));
    CHECK(batched.acc.a >= 0.95);
    KernelParams unterminated = s.p;
    unterminated.earlyTermination = 2;
    const Run same = scalarRun<std::uint8_t, false>(unterminated, ray, first + shift, batchEnd);
    CHECK(difference(same.acc, batched.acc) < 1e-6);
  }
}

// Each batch's voxels are fetched while the batch before it is classified
// (kernel_batch.h): the batch fetched ahead is taken while samples of the
// run remain (the last 1 to 7 as a masked batch, batch_tail_test.cpp), and
// one fetched ahead of the batch that terminates the ray is dropped. Runs
// of every length from 1 to 40 samples, starting at every offset within a
// cell pair: the batches take the whole run and stop at its end, with what
// the scalar loop composites.
TEST_CASE("batches fetched ahead are taken for every run length", "[raycast]") {
  const GridGeometry grid = cubeGrid(33);
  const Brick wave = makeVolume(grid, ScalarType::kUInt8,
                                [](Vec3 q) { return 127.5 + 120 * std::sin(q.x * 0.7) * std::cos(q.y * 0.2); });
  const TransferFunctionSpec tf = transfer({{0.0, 0, 0, 0, 0}, {60.0, 0, 0, 0, 0}, {128.0, 0.9, 0.4, 0.2, 0.3},
                                            {200.0, 0.1, 0.6, 0.9, 0.05}, {255.0, 0.5, 0.5, 0.5, 0.2}});
  const RenderOptions o = makeOptions(0.31);
  Setup s(wave, tf, o);
  REQUIRE(s.p.clearBelow > 0);
  const RaySetup ray = alongX(9.5, 16.25, o.step);
  std::int64_t first = 0, last = 0;
  REQUIRE(kernel::sampleRange(s.p, ray, first, last));
  REQUIRE(last - first > 48);
  for (std::int64_t shift = 0; shift < 7; ++shift)
    for (std::int64_t length = 1; length <= 40; ++length) {
      const std::int64_t from = first + shift, to = from + length;
      const Run a = scalarRun<std::uint8_t, false>(s.p, ray, from, to);
      Run b;
      std::int64_t start = from;
      REQUIRE_FALSE(kernel::runBatched<std::uint8_t, false>(s.p, ray, start, to, b.acc, b.samples));
      INFO("shift " << shift << ", length " << length);
      CHECK(start == to);
      CHECK(b.samples == std::uint64_t(length));
      CHECK(a.samples == b.samples);
      CHECK(difference(a.acc, b.acc) < 1e-6);
    }
  // Terminated by the first batch of a longer run: the batch fetched
  // ahead is dropped, the run stops after eight samples.
  RenderOptions early = o;
  early.earlyTermination = 0.05;
  Setup e(wave, tf, early);
  int terminated = 0;
  for (std::int64_t from = first; from + 24 <= last; ++from) {
    Run b;
    std::int64_t start = from;
    if (!kernel::runBatched<std::uint8_t, false>(e.p, ray, start, from + 24, b.acc, b.samples)) continue;
    ++terminated;
    const Run a = scalarRun<std::uint8_t, false>(s.p, ray, from, start);  // not terminated: the whole batches
    CHECK(b.acc.a >= 0.05);
    CHECK((start - from) % 8 == 0);
    CHECK(b.samples == std::uint64_t(start - from));
    CHECK(difference(a.acc, b.acc) < 1e-6);
  }
  CHECK(terminated > 10);
}

}  // namespace pvr::core

#endif
