// A visible run's last 1 to 7 samples taken by runBatched
// (renderer/raycast/kernel_batch.h) as one more batch, its lanes past the
// run masked out, instead of one at a time by runScalar (cast_ray.h).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
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

using test::alongX;
using test::batchedRun;
using test::difference;
using test::Run;
using test::scalarRun;

// Bands of opaque and clear values across x, so that the samples just past
// a run are often visible: a tail lane that leaked would show.
double bands(Vec3 q) { return 0.5 + 0.45 * std::sin(q.x * 0.9) * std::cos(q.y * 0.21 + q.z * 0.13); }

TransferFunctionSpec bandsTransfer(double scale, double offset) {
  TransferFunctionSpec tf;
  tf.points = {{0.0, 0, 0, 0, 0}, {0.35, 0.2, 0.5, 1.0, 0}, {0.6, 1.0, 0.8, 0.3, 0.6}, {1.0, 0.9, 0.9, 0.9, 0.9}};
  for (TransferPoint& point : tf.points) point.scalar = point.scalar * scale + offset;
  tf.unitDistance = 1.0;
  return tf;
}

}  // namespace

// Identity: a run of length 8 q + t, t = 1..7, batched (q whole batches,
// then the tail of t as a batch with 8 - t lanes masked) equals the scalar
// loop over the same samples, up to the float rounding of each batch's
// "over" tree (a few ulp of its colour, kernel_batch_over.h; the lit
// lanes' gradients up to rounding, shade_lanes.h): within 1e-6 unshaded,
// 1e-5 shaded, as for whole batches (batch_kernel_test.cpp). Every run
// ends with `start` at its end and every sample counted; the samples past
// the run are often visible (checked: the whole eighth batch differs), so
// a lane not masked would differ by far more. int16 and uint8 voxels (one
// gather per corner pair), float32 with non-finite voxels (masked as well);
// unshaded and shaded; rays of a perspective view; indices by multiplies
// and by shifts.
TEST_CASE("a run's last samples as a masked batch equal the scalar samples", "[raycast]") {
  // 32: strides of powers of two, voxel indices by shifts (voxelIndex8).
  const std::int64_t n = GENERATE(40, 32);
  const GridGeometry grid = cubeGrid(n);
  using Case = test::ScaledType;
  const Camera camera = test::obliqueView(grid, 12);
  for (const Case& k : {Case{ScalarType::kInt16, 60000, -30000}, Case{ScalarType::kUInt8, 255, 0},
                        Case{ScalarType::kFloat32, 1, 0}}) {
    const Brick volume = makeVolume(grid, k.type, [&](Vec3 q) {
      if (k.type == ScalarType::kFloat32 && int(q.x) % 7 == 3 && int(q.y) % 5 == 2)
        return std::numeric_limits<double>::quiet_NaN();
      return bands(q) * k.scale + k.offset;
    });
    for (bool shaded : {false, true}) {
      const RenderOptions o = makeOptions(0.45, false, shaded);
      const KernelFixture s(volume, bandsTransfer(k.scale, k.offset), o);
      REQUIRE(s.p.indices32);
      REQUIRE((s.p.strideShift[0] >= 0) == (n == 32));
      double worst = 0;
      int runs = 0, leakWouldShow = 0;
      for (int y = 0; y < camera.height(); ++y)
        for (int x = 0; x < camera.width(); ++x) {
          const RaySetup ray = raySetup(camera.ray(x, y), grid, o.step, normalize(Vec3{0.2, 0.4, -1}));
          std::int64_t first = 0, last = 0;
          if (!kernel::sampleRange(s.p, ray, first, last) || last - first < 40) continue;
          for (std::int64_t from = first; from + 24 <= last; from += 5)
            for (std::int64_t length = 1; length <= 23; ++length) {
              if (length % 8 == 0) continue;
              dispatchScalar(k.type, [&](auto tag) {
                using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
                const Run a = shaded ? scalarRun<T, true>(s.p, ray, from, from + length)
                                     : scalarRun<T, false>(s.p, ray, from, from + length);
                const Run b = shaded ? batchedRun<T, true>(s.p, ray, from, from + length)
                                     : batchedRun<T, false>(s.p, ray, from, from + length);
                INFO("from " << from << ", length " << length);
                CHECK_FALSE(b.terminated);
                CHECK(b.stoppedAt == from + length);
                CHECK(b.samples == std::uint64_t(length));
                CHECK(a.samples == b.samples);
                worst = std::max(worst, difference(a.acc, b.acc));
                // The run with its tail's batch unmasked: the samples up to
                // that batch's end.
                const std::int64_t unmasked = from + (length + 7) / 8 * 8;
                const Run all = shaded ? scalarRun<T, true>(s.p, ray, from, unmasked)
                                       : scalarRun<T, false>(s.p, ray, from, unmasked);
                leakWouldShow += difference(all.acc, a.acc) > 1e-3;
              });
              ++runs;
            }
        }
      INFO(int(k.type) << (shaded ? " shaded" : " unshaded") << ": " << runs << " runs, " << leakWouldShow
                       << " with visible samples past the run, max difference " << worst);
      CHECK(runs > 1000);
      CHECK(leakWouldShow > runs / 4);
      CHECK(worst < (shaded ? 1e-5 : 1e-6));
    }
  }
}

// Early termination is tested after the tail's batch as after any batch:
// a ray whose opacity passes the threshold within the tail's samples stops
// at the run's end, with what the scalar loop composites over all of them.
// Tails of 1 to 7 after a whole batch, shaded and not, int16 and uint8.
TEST_CASE("early termination within a run's tail stops at the run's end", "[raycast]") {
  const GridGeometry grid = cubeGrid(40);
  for (ScalarType type : {ScalarType::kInt16, ScalarType::kUInt8}) {
    const bool uint8 = type == ScalarType::kUInt8;
    const double scale = uint8 ? 255 : 60000, offset = uint8 ? 0 : -30000;
    const Brick volume = makeVolume(grid, type, [&](Vec3 q) { return bands(q) * scale + offset; });
    for (bool shaded : {false, true}) {
      RenderOptions o = makeOptions(0.45, false, shaded);
      o.earlyTermination = 0.5;
      const KernelFixture s(volume, bandsTransfer(scale, offset), o);
      KernelParams unterminated = s.p;
      unterminated.earlyTermination = 2;
      int inTail = 0;
      for (double y : {6.5, 13.25, 20.0, 27.75}) {
        const RaySetup ray = alongX(y, 31.0 - y * 0.5, o.step);
        std::int64_t first = 0, last = 0;
        REQUIRE(kernel::sampleRange(s.p, ray, first, last));
        for (std::int64_t from = first; from + 16 <= last; ++from)
          for (std::int64_t tail = 1; tail <= 7; ++tail) {
            const std::int64_t to = from + 8 + tail;
            dispatchScalar(type, [&](auto tag) {
              using T = std::remove_const_t<std::remove_pointer_t<decltype(tag)>>;
              const Run a = shaded ? scalarRun<T, true>(s.p, ray, from, to) : scalarRun<T, false>(s.p, ray, from, to);
              // The scalar loop stops within the tail's samples.
              if (!a.terminated || a.samples <= 8) return;
              ++inTail;
              const Run b = shaded ? batchedRun<T, true>(s.p, ray, from, to) : batchedRun<T, false>(s.p, ray, from, to);
              const Run whole = shaded ? scalarRun<T, true>(unterminated, ray, from, to)
                                       : scalarRun<T, false>(unterminated, ray, from, to);
              INFO("from " << from << ", tail " << tail << ", scalar stopped after " << a.samples);
              CHECK(b.terminated);
              CHECK(b.stoppedAt == to);
              CHECK(b.samples == std::uint64_t(8 + tail));
              CHECK(b.acc.a >= 0.5);
              CHECK(difference(whole.acc, b.acc) < (shaded ? 1e-5 : 1e-6));
            });
          }
      }
      INFO((uint8 ? "uint8" : "int16") << (shaded ? " shaded" : " unshaded") << ": " << inTail
                                       << " runs terminated in the tail");
      CHECK(inTail > 20);
    }
  }
}

}  // namespace pvr::core

#endif
