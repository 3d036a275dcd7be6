// A ray's visible chunks following on in the batch loop (cast_ray.h,
// RayWalk::step; kernel_batch.h, runBatched's `more`): the walk's next
// chunk, when it starts in a visible macrocell where this one's batches
// end, is taken without leaving the loop. The same look-ups, chunks and
// batches as one chunk a step, so the same bits.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "raycast/cast_ray.h"
#include "raycast/kernel_setup.h"
#include "raycast/macrocells.h"
#include "kernel_fixture.h"
#include "mixed_scenes.h"
#include "reference.h"
#include "transfer.h"

#ifdef PVR_HAVE_BATCH_KERNEL

namespace pvr::core {
namespace {

using test::tfOf;

// Blobs of different sizes with empty gaps between them along the rays, so
// that walks take runs of visible chunks, leap, and take more.
Brick blobsVolume() {
  const GridGeometry grid = cubeGrid(48);
  return makeVolume(grid, ScalarType::kUInt8, [](Vec3 q) {
    const Vec3 centres[3] = {{14, 16, 18}, {32, 30, 28}, {24, 36, 12}};
    const double radii[3] = {6, 8, 4};
    double v = 0;
    for (int b = 0; b < 3; ++b) {
      const Vec3 r = q - centres[b];
      v = std::max(v, 200.0 * std::exp(-dot(r, r) / (2 * radii[b] * radii[b])));
    }
    return v;
  });
}

struct Walked {
  RayResult result;
  int chunks = 0;          // chunks taken
  int followingOn = 0;     // chunks that start where the chunk before them ended
  int lookUps = 0;         // pastEmpty() calls
  int afterChunk = 0;      // look-ups where a chunk ended
  int emptyAfterChunk = 0; // of those, the ones that found nothing visible
  bool whole = true;       // every chunk whole batches, off the chord's ends
};

// The walk of RayWalk, one chunk a step, each chunk a runSpan of its own
// (no follow-on): the reference. Rays with no sample in the brick: none.
template <bool kShaded>
Walked chunkPerStep(const KernelParams& p, const RaySetup& ray, int shift) {
  Walked w;
  kernel::Accumulator acc;
  std::int64_t first = 0, last = -1;
  if (!kernel::sampleRange(p, ray, first, last)) return w;
  w.result.hit = true;
  std::int64_t k = first, end = last;
  if (kernel::clipToWalk(p, ray, kernel::TileSpan{}, k, end)) {
    const kernel::ChordEnds ends = kernel::chordEnds(p, ray, first, last);
    float o[3], d[3];
    for (int a = 0; a < 3; ++a) {
      o[a] = float(ray.origin[a]);
      d[a] = float(ray.step[a]);
    }
    const std::int64_t chunk = kernel::visibleChunk(ray);
    const kernel::CubeExit cube(ray, shift);
    const std::uint8_t* field = p.leapField[kernel::octantOf(ray)];
    std::int64_t lastExit = -1;
    while (k <= end) {
      const std::int64_t next = kernel::pastEmpty(p, field, cube, o, d, k, shift);
      ++w.lookUps;
      w.afterChunk += k == lastExit;
      if (next != k) {
        w.emptyAfterChunk += k == lastExit;
        k = next;
        continue;
      }
      const std::int64_t exit = std::min(last + 1, k + chunk);
      w.whole = w.whole && k > ends.first && exit <= ends.last && (exit - k) % 8 == 0;
      ++w.chunks;
      w.followingOn += k == lastExit;
      if (kernel::runSpan<std::uint8_t, kShaded, false>(p, ray, ends, k, exit, acc, w.result.samples)) break;
      k = lastExit = exit;
    }
  }
  w.result.colour = acc.rgba();
  return w;
}

}  // namespace

// Every ray of views from three sides, unshaded and shaded, with and
// without early termination: castRay (chunks following on) gives exactly
// the colour and sample count of the walk taking one chunk a step, and
// the views hold thousands of chunks that follow on.
TEST_CASE("chunks that follow on in the batch loop equal one chunk a step", "[raycast]") {
  const Brick volume = blobsVolume();
  const TransferFunctionSpec tf =
      tfOf({{0, 0, 0, 0, 0}, {30, 0.2, 0.5, 0.9, 0}, {120, 0.4, 0.8, 0.6, 0.08}, {200, 1, 0.5, 0.2, 0.3}}, 1.0);
  const Vec3 c = volume.grid().center();
  const std::vector<Camera> cameras = {
      makeCamera(Projection::kPerspective, c + Vec3{60, -80, 45}, c, {0, 0, 1}, 40, 48, 48),
      makeCamera(Projection::kOrthographic, c + Vec3{0, -90, 0}, c, {0, 0, 1}, 60, 48, 48),
      makeCamera(Projection::kPerspective, c + Vec3{-50, 20, -70}, c, {0, 1, 0}, 45, 48, 48)};
  for (bool shaded : {false, true}) {
    for (double early : {1.0, 0.6}) {
      for (double step : {0.5, 0.3}) {
        INFO((shaded ? "shaded" : "unshaded") << ", early termination " << early << ", step " << step);
        RenderOptions o = makeOptions(step, false, shaded);
        o.earlyTermination = float(early);
        const KernelFixture params(volume, tf, o, true);
        const KernelParams& p = params.p;
        REQUIRE(p.indices32);
        int chunks = 0, followingOn = 0, hits = 0;
        for (const Camera& camera : cameras) {
          const Vec3 light = normalize(camera.toWorld(o.shading.lightDirection));
          for (int y = 0; y < camera.height(); ++y)
            for (int x = 0; x < camera.width(); ++x) {
              const RaySetup ray = raySetup(camera.ray(x, y), volume.grid(), o.step, light);
              const Walked reference = shaded ? chunkPerStep<true>(p, ray, MacrocellGrid::kShift)
                                              : chunkPerStep<false>(p, ray, MacrocellGrid::kShift);
              if (!reference.result.hit) continue;
              const RayResult walked = shaded ? castRay<std::uint8_t, true, false>(p, ray, MacrocellGrid::kShift)
                                              : castRay<std::uint8_t, false, false>(p, ray, MacrocellGrid::kShift);
              INFO("pixel " << x << ", " << y);
              CHECK(walked.samples == reference.result.samples);
              CHECK(walked.colour.r == reference.result.colour.r);
              CHECK(walked.colour.g == reference.result.colour.g);
              CHECK(walked.colour.b == reference.result.colour.b);
              CHECK(walked.colour.a == reference.result.colour.a);
              chunks += reference.chunks;
              followingOn += reference.followingOn;
              hits += walked.colour.a > 0;
            }
        }
        // Chunks that follow on, and chunks that do not (after a leap).
        CHECK(followingOn > 1000);
        CHECK(chunks - followingOn > 1000);
        CHECK(hits > 1000);
      }
    }
  }
}

// A walk looks a sample up once: where a chunk's batches end, the batch
// loop looks up the next chunk (RayWalk::step's `chunks`), and when it
// finds it empty the walk leaps from that look-up instead of making it
// again in its next step. On rays whose chunks are all whole batches off
// the chord's ends (so that the loop asks at every chunk's end), the walk
// takes one step for each look-up the chunk-a-step walk makes other than
// those where a chunk ended; and among those, hundreds found nothing
// visible (the look-ups a step made again before).
TEST_CASE("a walk looks up the sample after a chunk once", "[raycast]") {
  const Brick volume = blobsVolume();
  const TransferFunctionSpec tf =
      tfOf({{0, 0, 0, 0, 0}, {30, 0.2, 0.5, 0.9, 0}, {120, 0.4, 0.8, 0.6, 0.08}, {200, 1, 0.5, 0.2, 0.3}}, 1.0);
  const Vec3 c = volume.grid().center();
  const Camera camera = makeCamera(Projection::kPerspective, c + Vec3{60, -80, 45}, c, {0, 0, 1}, 40, 64, 64);
  for (double step : {0.5, 0.3}) {
    INFO("step " << step);
    const RenderOptions o = makeOptions(step);
    const KernelFixture params(volume, tf, o, true);
    const KernelParams& p = params.p;
    int rays = 0, emptyAfterChunk = 0;
    for (int y = 0; y < camera.height(); ++y)
      for (int x = 0; x < camera.width(); ++x) {
        const RaySetup ray = raySetup(camera.ray(x, y), volume.grid(), o.step, Vec3{0, 0, 1});
        const Walked reference = chunkPerStep<false>(p, ray, MacrocellGrid::kShift);
        if (!reference.result.hit || reference.chunks == 0 || !reference.whole) continue;
        kernel::RayWalk<std::uint8_t, false, false> walk;
        RayResult out;
        int steps = 0;
        if (walk.start(p, ray, MacrocellGrid::kShift, kernel::TileSpan{}, out))
          do ++steps;
          while (walk.step(p, ray, MacrocellGrid::kShift, out));
        INFO("pixel " << x << ", " << y);
        CHECK(out.colour.a == reference.result.colour.a);
        CHECK(steps == reference.lookUps - reference.afterChunk);
        ++rays;
        emptyAfterChunk += reference.emptyAfterChunk;
      }
    CHECK(rays > 300);
    CHECK(emptyAfterChunk > 300);
  }
}

// runBatched's `more`, alone: a run of 16 samples whose batches follow on
// once by 24 more equals one run of 40; one that declines stops at 16; and
// `more` is asked only where whole batches end exactly at the run's end.
TEST_CASE("a batch loop that follows on equals one longer run", "[raycast]") {
  const Brick volume = blobsVolume();
  const TransferFunctionSpec tf = tfOf({{0, 0, 0, 0, 0}, {30, 0.2, 0.5, 0.9, 0}, {200, 1, 0.5, 0.2, 0.1}}, 1.0);
  const RenderOptions o = makeOptions(0.37);
  const KernelFixture params(volume, tf, o, false);
  const KernelParams& p = params.p;
  RaySetup ray{};
  ray.origin[1] = 16.3;
  ray.origin[2] = 17.8;
  ray.step[0] = o.step;
  ray.invStep[0] = 1 / o.step;
  ray.leapPerMacrocell = MacrocellGrid::kSize / o.step;
  std::int64_t first = 0, last = 0;
  REQUIRE(kernel::sampleRange(p, ray, first, last));
  int composited = 0;
  for (std::int64_t from = first; from + 40 <= last; from += 3) {
    kernel::Accumulator whole, followed, declined;
    std::uint64_t wholeSamples = 0, followedSamples = 0, declinedSamples = 0;
    std::int64_t a = from, b = from, c = from;
    REQUIRE_FALSE(kernel::runBatched<std::uint8_t, false>(p, ray, a, from + 40, whole, wholeSamples));
    std::vector<std::int64_t> asked;
    auto once = [&](std::int64_t at) {
      asked.push_back(at);
      return asked.size() == 1 ? at + 24 : at;
    };
    REQUIRE_FALSE(kernel::runBatched<std::uint8_t, false>(p, ray, b, from + 16, followed, followedSamples, once));
    auto never = [](std::int64_t at) { return at; };
    REQUIRE_FALSE(kernel::runBatched<std::uint8_t, false>(p, ray, c, from + 16, declined, declinedSamples, never));
    INFO("from " << from);
    CHECK(asked == std::vector<std::int64_t>{from + 16, from + 40});
    CHECK(a == from + 40);
    CHECK(b == from + 40);
    CHECK(c == from + 16);
    CHECK(followedSamples == 40);
    CHECK(declinedSamples == 16);
    CHECK(followed.r == whole.r);
    CHECK(followed.g == whole.g);
    CHECK(followed.b == whole.b);
    CHECK(followed.a == whole.a);
    composited += whole.a > declined.a;
    // Batches that end short of the run's end: `more` is not asked; the
    // run's last samples are a batch of their own (batch_tail_test.cpp).
    std::int64_t d = from;
    kernel::Accumulator partial;
    std::uint64_t partialSamples = 0;
    asked.clear();
    REQUIRE_FALSE(kernel::runBatched<std::uint8_t, false>(p, ray, d, from + 21, partial, partialSamples, once));
    CHECK(asked.empty());
    CHECK(d == from + 21);
    CHECK(partialSamples == 21);
  }
  CHECK(composited > 3);
}

}  // namespace pvr::core

#endif
