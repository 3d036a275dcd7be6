// Pre-integration (renderer/preintegration.h) on single segments, against
// the emission-absorption integral of the same segment with the scalar
// linear along it, integrated on a million substeps in double; beside what
// plain point sampling makes of the same segment (the one-step table at the
// segment's middle scalar, as the plain kernel classifies).
#include <catch2/catch.hpp>

#include <cmath>
#include <tuple>
#include <vector>

#include "raycast/cast_ray.h"
#include "raycast/kernel_setup.h"
#include "raycast/macrocells.h"
#include "preintegrated_kernel.h"
#include "reference.h"
#include "transfer.h"

namespace pvr::core {
namespace {


// The segment's integral: the scalar runs linearly from `front` to `back`
// over `length`; midpoint rule on n substeps, each attenuating exactly.
RgbaD integrateSegment(const TransferFunctionSpec& tf, double front, double back, double length,
                       int n = 1000000) {
  RgbaD out;
  double transmittance = 1;
  const double dt = length / n;
  for (int i = 0; i < n; ++i) {
    const Medium m = evaluateMedium(tf, front + (back - front) * (i + 0.5) / n);
    const double alpha = -std::expm1(-m.tau * dt);
    out.r += transmittance * alpha * m.r;
    out.g += transmittance * alpha * m.g;
    out.b += transmittance * alpha * m.b;
    transmittance *= 1 - alpha;
  }
  out.a = 1 - transmittance;
  return out;
}

Rgba preintegrated(const PreintegratedTable& table, double front, double back, double length) {
  const PreintegralTables t = table.tables();
  return preint::segment(t, preint::endAt(t, float(front)), preint::endAt(t, float(back)), length);
}

// Plain sampling's segment: the table of one step `length` at the middle scalar.
Rgba plain(const TransferFunctionSpec& tf, double front, double back, double length) {
  const TransferTable table(tf, length);
  KernelParams p;
  setTables(p, table, nullptr, length);
  return kernel::classify1D(p, float(0.5 * (front + back)));
}

double difference(const Rgba& p, const RgbaD& q) {
  return std::max({std::abs(p.r - q.r), std::abs(p.g - q.g), std::abs(p.b - q.b), std::abs(p.a - q.a)});
}

struct Segment {
  const char* name;
  TransferFunctionSpec tf;
  double front, back, length;
  double bound;  // on the pre-integrated error
};

// A narrow peak, 1% of the scalar range wide, with a colour change across it.
TransferFunctionSpec peak() {
  return transfer({{0.0, 0, 0, 0, 0},
                   {0.49, 0.2, 0.5, 1.0, 0},
                   {0.5, 1.0, 0.8, 0.3, 0.9},
                   {0.51, 0.2, 0.9, 0.3, 0},
                   {1.0, 0, 0, 0, 0}});
}

#ifdef PVR_HAVE_BATCH_KERNEL
// Segments [first, last) of a ray one at a time, and batched (with the rest
// one at a time): the largest difference of the two results' channels.
template <typename V, bool kShaded>
double batchedAgainstScalar(const KernelParams& p, const RaySetup& ray, std::int64_t first,
                            std::int64_t last) {
  kernel::Accumulator scalar, batched;
  std::uint64_t n1 = 0, n2 = 0;
  kernel::runScalar<V, kShaded, true>(p, ray, first, last, scalar, n1);
  std::int64_t start = first;
  kernel::runBatchedPreintegrated<V, kShaded>(p, ray, start, last, batched, n2);
  kernel::runScalar<V, kShaded, true>(p, ray, start, last, batched, n2);
  if (n1 != n2) return 1.0;
  return std::max({std::abs(scalar.r - batched.r), std::abs(scalar.g - batched.g),
                   std::abs(scalar.b - batched.b), std::abs(scalar.a - batched.a)});
}
#endif

}  // namespace

// Identity: where the transfer function bends between a segment's end
// scalars (a peak crossed, a thin feature stepped over), pre-integration
// integrates what lies between them, to float rounding plus the
// piecewise-linear tabulation (4096 nodes: 1e-4 of the peak's opacity
// measured at most); point sampling sees one scalar only. Its error must be
// below plain's, and below 2e-3 absolute where the colour does not change
// inside a dense part of the segment. Where it does, the segment's mean
// colour stands for colours it attenuates unevenly (preintegration.h): the
// ramp into a dense range (alpha 0.75) is off by 0.07 (plain: 0.09), the
// step to a dense blue behind a faint red by 3.4e-3 (plain: 0.16); bounds
// 0.08 and 5e-3.
TEST_CASE("a pre-integrated segment across a sharp transfer function matches its integral",
          "[preintegration]") {
  const Segment cases[] = {
      {"peak crossed upwards", peak(), 0.3, 0.7, 1.0, 2e-3},
      {"peak crossed downwards", peak(), 0.62, 0.45, 2.0, 2e-3},
      {"peak crossed, short step", peak(), 0.48, 0.53, 0.25, 2e-3},
      {"thin feature stepped over at a large step", peak(), 0.1, 0.9, 4.0, 2e-3},
      {"ramp into a dense range", transfer({{0, 0.1, 0.2, 0.3, 0}, {10, 1, 1, 1, 0.95}}), 2, 9.5, 1.5,
       0.08},
      {"steps in opacity and colour",
       transfer({{0, 0.9, 0.1, 0.1, 0.02}, {0.3, 0.9, 0.1, 0.1, 0.02}, {0.31, 0.1, 0.1, 0.9, 0.7},
                 {1, 0.1, 0.1, 0.9, 0.7}}),
       0.2, 0.5, 1.0, 5e-3},
  };
  for (const Segment& s : cases) {
    const PreintegratedTable table(s.tf);
    const RgbaD exact = integrateSegment(s.tf, s.front, s.back, s.length);
    const double pre = difference(preintegrated(table, s.front, s.back, s.length), exact);
    const double point = difference(plain(s.tf, s.front, s.back, s.length), exact);
    INFO(s.name << ": alpha " << exact.a << ", pre-integrated error " << pre << ", plain error " << point);
    CHECK(pre < s.bound);
    CHECK(pre < point);
  }
}

// Identity: a segment whose scalar does not change (s_front == s_back), or
// whose transfer function is constant between its ends, is a homogeneous
// medium: alpha = 1 - exp(-tau L), colour c alpha, for any length. Both
// pre-integration and plain sampling give it to float rounding (1e-6);
// ends a hair apart (below preint::kMinSpan) give the same.
TEST_CASE("a pre-integrated constant segment is the closed form", "[preintegration]") {
  const TransferFunctionSpec soft = transfer({{0, 0, 0, 0, 0}, {0.2, 0.1, 0.3, 0.9, 0.02},
                                              {0.5, 0.9, 0.6, 0.2, 0.15}, {1, 1, 1, 1, 0.4}});
  const TransferFunctionSpec flat = transfer({{0, 0.9, 0.5, 0.2, 0.3}, {1, 0.9, 0.5, 0.2, 0.3}});
  const PreintegratedTable softTable(soft), flatTable(flat);
  for (double length : {0.01, 0.5, 1.0, 3.0}) {
    for (double s : {0.0, 0.1234, 0.35, 0.77, 1.0}) {
      INFO("length " << length << ", scalar " << s);
      const RgbaD exact = constantMedium(evaluateMedium(soft, s), length);
      CHECK(difference(preintegrated(softTable, s, s, length), exact) < 1e-6);
      CHECK(difference(preintegrated(softTable, s, s + 1e-7, length), exact) < 1e-6);
      // Constant transfer function, ends apart: still homogeneous.
      const RgbaD flatExact = constantMedium(evaluateMedium(flat, 0), length);
      CHECK(difference(preintegrated(flatTable, s, 1 - s, length), flatExact) < 1e-6);
    }
  }
}

// Identity: outside its control points the transfer function is clamped,
// so a segment running beyond them integrates the end points' medium over
// the part outside (error as for the sharp cases, 2e-3 at most); an opaque
// scalar (opacity 1) anywhere in a segment makes it opaque, with the colour
// of the first opaque scalar met from its front.
TEST_CASE("pre-integrated segments beyond the control points and through opaque scalars",
          "[preintegration]") {
  const TransferFunctionSpec ramp = transfer({{10, 0.2, 0.4, 0.6, 0.05}, {20, 0.8, 0.6, 0.4, 0.3}});
  const PreintegratedTable rampTable(ramp);
  for (auto [f, b] : {std::pair{-50.0, 15.0}, {12.0, 70.0}, {-5.0, 40.0}, {30.0, 25.0}}) {
    INFO("scalars " << f << " to " << b);
    const RgbaD exact = integrateSegment(ramp, f, b, 1.0);
    CHECK(difference(preintegrated(rampTable, f, b, 1.0), exact) < 2e-3);
  }
  const TransferFunctionSpec wall = transfer({{0, 0.5, 0.5, 0.5, 0.1}, {0.5, 0.5, 0.5, 0.5, 0.1},
                                              {0.6, 1.0, 0.0, 0.0, 1.0}, {0.7, 0.0, 0.0, 1.0, 1.0},
                                              {0.8, 0.5, 0.5, 0.5, 0.1}, {1, 0.5, 0.5, 0.5, 0.1}});
  const PreintegratedTable wallTable(wall);
  const Rgba up = preintegrated(wallTable, 0.2, 0.9, 0.1);
  const Rgba down = preintegrated(wallTable, 0.95, 0.3, 0.1);
  CHECK(up.a == 1.0f);
  CHECK(down.a == 1.0f);
  CHECK((up.r > 0.95f && up.b < 0.05f));    // met red first going up
  CHECK((down.b > 0.95f && down.r < 0.05f));  // met blue first going down
  CHECK(preintegrated(wallTable, 0.65, 0.65, 1e-6).a == 1.0f);
  CHECK(preintegrated(wallTable, 0.1, 0.3, 0.5).a < 0.1f);
}

// Identity: the segment model takes the scalar linear between nodes; the
// nodes corrected from their neighbours (curvedNode()) give each segment
// the mean scalar of the cubic through the four samples around it, exact
// for a quadratic field: s = t^2 sampled at integers, segment [k, k + 1]
// has mean k^2 + k + 1/3 (float rounding: 1e-4 at k = 40). A corrected node
// stays inside its cell's range.
TEST_CASE("pre-integration's nodes follow the field's curvature", "[preintegration]") {
  for (int k = -3; k < 40; ++k) {
    auto s = [](double t) { return float(t * t); };
    const float front = kernel::curvedNode<float>(s(k - 1), s(k), s(k + 1), -1e9f, 1e9f);
    const float back = kernel::curvedNode<float>(s(k), s(k + 1), s(k + 2), -1e9f, 1e9f);
    INFO("segment " << k);
    CHECK(std::abs(0.5 * (double(front) + double(back)) - (k * k + k + 1.0 / 3)) < 1e-4 * (1 + k * k));
  }
  CHECK(kernel::curvedNode<float>(0, 1, 0, 0, 1) == 1.0f);           // peak: held at the cell's top
  CHECK(kernel::curvedNode<float>(1, 0.5f, 0, 0, 1) == 0.5f);        // straight: unchanged
  CHECK(kernel::curvedNode<float>(NAN, 0.5f, 0, 0, 1) == 0.5f);      // non-finite neighbour
}

// Identity: a pre-integrated segment is lit at the centroid of what it
// emits, the extinction weighted by the light still passing:
// t tau(t) exp(-int_0^t tau) over its length, for which a homogeneous
// segment of optical depth D has the closed form 1/D - 1/(e^D - 1) and a
// linear ramp of extinction a first-order one (2.9e-3 of the length at
// most measured, bound 5e-3; lighting at the middle is off by up to 0.15).
TEST_CASE("a pre-integrated segment is lit at the centre of its emission", "[preintegration]") {
  const TransferFunctionSpec ramp = transfer({{0, 1, 1, 1, 0.0}, {1, 1, 1, 1, 0.3}});
  const PreintegratedTable table(ramp);
  const PreintegralTables t = table.tables();
  for (auto [f, b, length] : {std::tuple{0.5, 0.5, 1.0}, {0.9, 0.9, 6.0}, {0.1, 0.9, 1.0}, {0.9, 0.2, 2.0},
                              {0.05, 0.6, 0.5}, {0.7, 0.3, 1.0}}) {
    float centre = -1;
    preint::segment(t, preint::endAt(t, float(f)), preint::endAt(t, float(b)), length, &centre);
    // The centroid by a million substeps.
    const int n = 1000000;
    double depth = 0, weight = 0, moment = 0;
    for (int i = 0; i < n; ++i) {
      const double u = (i + 0.5) / n, tau = evaluateMedium(ramp, f + (b - f) * u).tau;
      const double w = tau * std::exp(-depth);
      weight += w;
      moment += w * u;
      depth += tau * length / n;
    }
    INFO("scalars " << f << " to " << b << ", length " << length << ": centre " << centre << ", exact "
                    << moment / weight);
    CHECK(std::abs(centre - moment / weight) < 5e-3);
  }
}

// The emission's spread of a thin segment: the series below depth 1e-2
// and the closed form above it are the same variance of t under e^(-D t)
// on [0, 1] (here by a midpoint sum); the series had D^2/720 for D^2/240
// once, 2.8e-7 off at the switch.
TEST_CASE("a thin segment's emission variance is the variance of its emission", "[preintegration]") {
  for (const double depth : {1e-4, 5e-3, 0.0099999, 0.0100001, 0.05, 0.5, 3.0}) {
    const int n = 200000;
    double weight = 0, moment = 0, square = 0;
    for (int i = 0; i < n; ++i) {
      const double t = (i + 0.5) / n, w = std::exp(-depth * t);
      weight += w;
      moment += w * t;
      square += w * t * t;
    }
    const double mean = moment / weight, exact = square / weight - mean * mean;
    INFO("depth " << depth);
    CHECK(std::abs(preint::emissionVariance(depth, -std::expm1(-depth)) - exact) < 1e-10);
  }
}

#ifdef PVR_HAVE_BATCH_KERNEL
// Identity: the batched pre-integrated kernel (eight back ends per batch)
// composites the same segments in the same order as the one-at-a-time
// loop; they differ only in how float positions and interpolations round
// (fused multiply-adds), 1e-5 at most over a ray of ~100 segments
// through a dense, sharply classified volume. Every ray of a view, shaded
// and unshaded, uint8 and float32.
TEST_CASE("the batched pre-integrated kernel equals the scalar kernel", "[preintegration]") {
  const std::int64_t n = GENERATE(40, 32);  // voxel indices by multiplies, by shifts (voxelIndex8)
  const GridGeometry grid = cubeGrid(n);
  auto field = [](Vec3 q) {
    return 0.5 + 0.45 * std::sin(q.x * 0.31) * std::cos(q.y * 0.23 + q.z * 0.17);
  };
  const TransferFunctionSpec tf = transfer({{0.0, 0, 0, 0, 0},
                                            {0.3, 0.2, 0.5, 1.0, 0.02},
                                            {0.5, 1.0, 0.8, 0.3, 0.5},
                                            {0.52, 0.2, 0.9, 0.3, 0.05},
                                            {1.0, 0.9, 0.9, 0.9, 0.3}});
  const Brick volumes[] = {makeVolume(grid, ScalarType::kFloat32, field),
                           makeVolume(grid, ScalarType::kUInt8, [&](Vec3 q) { return 255 * field(q); })};
  const TransferFunctionSpec tf8 = [&] {
    TransferFunctionSpec t = tf;
    for (TransferPoint& point : t.points) point.scalar *= 255;
    return t;
  }();
  const Vec3 c = grid.center();
  const Camera camera = makeCamera(Projection::kPerspective, c - normalize(Vec3{0.3, 1, 0.5}) * 70.0, c,
                                   {0, 0, 1}, 40, 24, 24);
  for (const Brick& volume : volumes) {
    const TransferFunctionSpec& f = volume.type() == ScalarType::kUInt8 ? tf8 : tf;
    for (bool shaded : {false, true}) {
      const RenderOptions o = makeOptions(0.45, true, shaded);
      const PreintegratedKernel setup(volume, f, o);
      const KernelParams& p = setup.params();
      REQUIRE(p.indices32);
      REQUIRE((p.strideShift[0] >= 0) == (n == 32));
      double worst = 0;
      int rays = 0;
      setup.forEachRay(camera, grid, o.step, [&](const RaySetup& ray, std::int64_t first, std::int64_t last) {
        if (last - first < 20) return;
        const bool uint8 = volume.type() == ScalarType::kUInt8;
        const double difference =
            uint8 ? (shaded ? batchedAgainstScalar<std::uint8_t, true>(p, ray, first, last)
                            : batchedAgainstScalar<std::uint8_t, false>(p, ray, first, last))
                  : (shaded ? batchedAgainstScalar<float, true>(p, ray, first, last)
                            : batchedAgainstScalar<float, false>(p, ray, first, last));
        worst = std::max(worst, difference);
        ++rays;
      });
      INFO((volume.type() == ScalarType::kUInt8 ? "uint8" : "float32")
           << (shaded ? " shaded" : " unshaded") << ": " << rays << " rays, max difference " << worst);
      CHECK(rays > 100);
      CHECK(worst < 1e-5);
    }
  }
}

// The next batch's samples are fetched before a batch's empty test
// (kernel_batch.h runBatchedPreintegrated): fetched only when a next batch
// runs, and dropped when the ray terminates. Runs of every length from 1 to
// 40 segments at every offset within a batch, lit and unlit, equal the
// scalar kernel; runs cut short by early termination equal the scalar
// kernel over the segments they took.
TEST_CASE("pre-integrated batches fetched ahead are taken for every run length", "[preintegration]") {
  const GridGeometry grid = cubeGrid(40);
  const Brick volume = makeVolume(grid, ScalarType::kUInt8, [](Vec3 q) {
    return 255 * (0.5 + 0.45 * std::sin(q.x * 0.31) * std::cos(q.y * 0.23 + q.z * 0.17));
  });
  const TransferFunctionSpec tf = transfer({{0.0, 0, 0, 0, 0},
                                            {60.0, 0, 0, 0, 0},
                                            {128.0, 1.0, 0.8, 0.3, 0.5},
                                            {140.0, 0.2, 0.9, 0.3, 0.05},
                                            {255.0, 0.9, 0.9, 0.9, 0.3}});
  const Vec3 c = grid.center();
  const Camera camera = makeCamera(Projection::kPerspective, c - normalize(Vec3{0.3, 1, 0.5}) * 70.0, c,
                                   {0, 0, 1}, 40, 12, 12);
  for (bool shaded : {false, true}) {
    const RenderOptions o = makeOptions(0.45, true, shaded);
    const PreintegratedKernel setup(volume, tf, o);
    const KernelParams& p = setup.params();
    KernelParams early = p;
    early.earlyTermination = 0.05;
    KernelParams unterminated = p;
    unterminated.earlyTermination = 2;
    double worst = 0;
    int runs = 0, terminated = 0;
    setup.forEachRay(camera, grid, o.step, [&](const RaySetup& ray, std::int64_t first, std::int64_t last) {
      if (last - first < 48) return;
      for (std::int64_t shift = 0; shift < 8; ++shift)
        for (std::int64_t length = 1; length <= 40; ++length) {
          const std::int64_t from = first + shift, to = from + length;
          worst = std::max(worst, shaded ? batchedAgainstScalar<std::uint8_t, true>(p, ray, from, to)
                                         : batchedAgainstScalar<std::uint8_t, false>(p, ray, from, to));
          ++runs;
        }
      for (std::int64_t from = first; from + 24 <= last; from += 3) {
        kernel::Accumulator batched, scalar;
        std::uint64_t n1 = 0, n2 = 0;
        std::int64_t start = from;
        const bool stopped = shaded
            ? kernel::runBatchedPreintegrated<std::uint8_t, true>(early, ray, start, from + 24, batched, n1)
            : kernel::runBatchedPreintegrated<std::uint8_t, false>(early, ray, start, from + 24, batched, n1);
        if (!stopped) continue;
        ++terminated;
        if (shaded) kernel::runScalar<std::uint8_t, true, true>(unterminated, ray, from, start, scalar, n2);
        else kernel::runScalar<std::uint8_t, false, true>(unterminated, ray, from, start, scalar, n2);
        CHECK(batched.a >= 0.05);
        CHECK(n1 == std::uint64_t(start - from));
        CHECK(n1 == n2);
        worst = std::max({worst, std::abs(scalar.r - batched.r), std::abs(scalar.g - batched.g),
                          std::abs(scalar.b - batched.b), std::abs(scalar.a - batched.a)});
      }
    });
    INFO((shaded ? "shaded" : "unshaded") << ": " << runs << " runs, " << terminated
                                           << " terminated, max difference " << worst);
    CHECK(runs > 1000);
    CHECK(terminated > 10);
    CHECK(worst < 1e-5);
  }
}
#endif

}  // namespace pvr::core
