// Pre-integration eight segments at once (renderer/raycast/preint_lanes.h)
// against one at a time (renderer/preintegration.h), and the batched
// pre-integrated kernel against the scalar one where the lanes meet
// opacity 1, empty cells, non-finite voxels and runs shorter than a batch.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

#include "raycast/cast_ray.h"
#include "preintegrated_kernel.h"
#include "reference.h"
#include "transfer.h"

namespace pvr::core {
namespace {

// Empty below 0.2 and between 0.55 and 0.6, opaque from 0.8 to 0.85,
// colour changing throughout.
TransferFunctionSpec mixedTransfer() {
  TransferFunctionSpec tf;
  tf.points = {{0.0, 0, 0, 0, 0},      {0.2, 0.1, 0.2, 0.9, 0},   {0.3, 0.2, 0.5, 1.0, 0.05},
               {0.5, 1.0, 0.8, 0.3, 0.6}, {0.55, 0.9, 0.4, 0.3, 0}, {0.6, 0.9, 0.4, 0.3, 0},
               {0.7, 0.3, 0.9, 0.2, 0.2}, {0.8, 1.0, 0.1, 0.1, 1},  {0.85, 0.1, 0.1, 1.0, 1},
               {0.9, 0.5, 0.5, 0.5, 0.1}, {1.0, 0.9, 0.9, 0.9, 0.3}};
  tf.unitDistance = 1.0;
  return tf;
}

// Transfer functions with empty ends: low and high, low only, high only
// (index 2), low with gaps between visible ranges (index 3, mixedTransfer()),
// and no visible range at all.
std::vector<TransferFunctionSpec> emptyEndTransfers() {
  auto ramp = [](std::vector<TransferPoint> points) {
    TransferFunctionSpec tf;
    tf.points = std::move(points);
    tf.unitDistance = 1.0;
    return tf;
  };
  return {ramp({{0.0, 0, 0, 0, 0}, {0.3, 0.1, 0.2, 0.9, 0}, {0.5, 1.0, 0.8, 0.3, 0.6}, {0.7, 0.2, 0.2, 0.2, 0}, {1.0, 0, 0, 0, 0}}),
          ramp({{0.0, 0, 0, 0, 0}, {0.2, 0.1, 0.2, 0.9, 0}, {1.0, 0.9, 0.9, 0.9, 0.3}}),
          ramp({{0.0, 0.5, 0.5, 0.5, 0.2}, {0.6, 0.1, 0.2, 0.9, 0}, {1.0, 0, 0, 0, 0}}),
          mixedTransfer(),
          ramp({{0.0, 0, 0, 0, 0}, {1.0, 1, 1, 1, 0}})};
}

}  // namespace

#ifdef PVR_HAVE_PREINT_LANES
// Identity: expm1NonPositive(x) is expm1(x) for x <= 0 to the degree-8
// polynomial's remainder, relative 6e-10 (bound 1e-9; a term dropped or
// wrong errs by 3e-9 or more at x = -ln2 / 2), from tiny x where
// expm1(x) ~ x to x = -800.
TEST_CASE("the lanes expm1 is the library expm1", "[preintegration]") {
  std::vector<double> xs;
  for (double x = -1e-12; x > -800; x *= 1.37) xs.push_back(x);
  xs.push_back(0.0);
  while (xs.size() % 8) xs.push_back(-0.5);
  for (std::size_t i = 0; i < xs.size(); i += 8) {
    alignas(64) double out[8];
    _mm512_store_pd(out, preint::expm1NonPositive(_mm512_loadu_pd(&xs[i])));
    for (int j = 0; j < 8; ++j) {
      const double exact = std::expm1(xs[i + j]);
      INFO("x = " << xs[i + j]);
      CHECK(std::abs(out[j] - exact) <= 1e-9 * std::abs(exact));
    }
  }
}

// Identity: allClear() (the empty ends, lane by lane) never calls a batch
// empty that allEmpty() (the prefix count of visible cells over the
// batch's range) does not, and where the transfer function has no empty
// cells between visible ones (PreintegralTables::gaps false) the two agree
// on every batch. Scalars are drawn across the control points, beyond
// them, and at and around the clear ends' limits (where a coordinate's
// rounding decides). Transfer functions: clear at both ends, clear low
// end only, visible from the first node, with a gap, and all clear.
TEST_CASE("a batch in the transfer function's empty ends is empty by either test", "[preintegration]") {
  const std::vector<TransferFunctionSpec> tfs = emptyEndTransfers();
  std::mt19937 random(7);
  for (int which = 0; which < int(std::size(tfs)); ++which) {
    const PreintegratedTable table(tfs[which]);
    const PreintegralTables t = table.tables();
    INFO("transfer function " << which << ", clear below " << t.clearBelow << ", at or above " << t.clearAbove);
    CHECK(t.gaps == (which == 3));
    // Scalars whose table coordinates lie at a limit, a rounding either side, or anywhere.
    std::vector<float> limits;
    for (float x : {t.clearBelow, t.clearAbove})
      if (std::isfinite(x))
        for (float dx : {-1.5f, -1.0f, -0.5f, -1e-3f, 0.0f, 1e-3f, 0.5f, 1.0f, 1.5f})
          limits.push_back((x + dx - t.offset) / t.scale);
    std::uniform_real_distribution<float> anywhere(-0.2f, 1.2f);
    std::uniform_int_distribution<int> pick(0, 3);
    int clear = 0, empty = 0;
    for (int trial = 0; trial < 200000; ++trial) {
      // Batches that stay near one value, so that some lie wholly in an end.
      const float centre = limits.empty() || pick(random) == 0
                               ? anywhere(random)
                               : limits[std::size_t(random() % limits.size())];
      std::uniform_real_distribution<float> near(-0.02f, 0.02f);
      alignas(32) float s[8];
      for (float& x : s) x = pick(random) == 0 ? centre : centre + near(random);
      const float front = centre + near(random);
      const __m256 scalars = _mm256_load_ps(s);
      const bool byEnds = preint::allClear(t, scalars, front), byCount = preint::allEmpty(t, scalars, front);
      clear += byEnds;
      empty += byCount;
      if (byEnds) REQUIRE(byCount);
      if (!t.gaps) REQUIRE(byEnds == byCount);
    }
    INFO(clear << " batches clear by the ends, " << empty << " empty by the count");
    if (which != 2) CHECK(clear > 1000);
  }
}

// Identity: frontRow() gives a front in the transfer function's empty ends
// a constant row (all integrals 0 below, those at the last node above)
// instead of the table's; it equals rowEnd() there exactly, and is
// rowEnd() elsewhere. Scalars at the ends' limits, a rounding either side,
// beyond the table and anywhere; a constant from the wrong node, or the
// point values not 0, differs.
TEST_CASE("a pre-integrated front in the empty ends takes a constant row equal to the table's", "[preintegration]") {
  const std::vector<TransferFunctionSpec> tfs = emptyEndTransfers();
  std::mt19937 random(11);
  for (int which = 0; which < int(std::size(tfs)); ++which) {
    const PreintegratedTable table(tfs[which]);
    const PreintegralTables t = table.tables();
    INFO("transfer function " << which << ", clear below " << t.clearBelow << ", at or above " << t.clearAbove);
    std::vector<float> scalars;
    for (float x : {t.clearBelow, t.clearAbove})
      if (std::isfinite(x))
        for (float dx : {-1.5f, -1.0f, -0.5f, -1e-3f, -1e-5f, 0.0f, 1e-5f, 1e-3f, 0.5f, 1.0f, 1.5f})
          scalars.push_back((x + dx - t.offset) / t.scale);
    std::uniform_real_distribution<float> anywhere(-0.3f, 1.3f);
    for (int n = 0; n < 20000; ++n) scalars.push_back(anywhere(random));
    int constant = 0, unequal = 0;
    for (float scalar : scalars) {
      const float at = std::fma(scalar, t.scale, t.offset);
      constant += at < t.clearBelow || at >= t.clearAbove;
      const preint::RowEnd a = preint::frontRow(t, scalar), b = preint::rowEnd(t, scalar);
      alignas(64) double ra[8], rb[8];
      _mm512_store_pd(ra, a.row);
      _mm512_store_pd(rb, b.row);
      bool same = a.x == b.x;
      for (int k = 0; k < 8; ++k) same = same && ra[k] == rb[k];
      if (!same) {
        ++unequal;
        UNSCOPED_INFO("scalar " << scalar << ": T " << ra[0] << " against " << rb[0] << ", tau " << ra[4]
                                << " against " << rb[4] << ", x " << a.x << " against " << b.x);
      }
    }
    INFO(constant << " of " << scalars.size() << " fronts in an empty end");
    CHECK(unequal == 0);
    if (which != 2) CHECK(constant > 1000);
  }
}

// Identity: segments() of eight (front, back) pairs is segment() of each
// pair, the opaque lanes flagged rather than coloured; the lanes use the
// reciprocal estimate refined once or twice and an FMA where segment()
// divides, and a degree-8 expm1, so they agree to 1e-8, below the float
// they return (bound 1e-7 on colour, opacity and centre). Scalars are drawn across the
// control points and beyond, with ends equal, a hair apart (below
// preint::kMinSpan) and far apart.
TEST_CASE("eight pre-integrated segments at once equal one at a time", "[preintegration]") {
  const TransferFunctionSpec tf = mixedTransfer();
  const PreintegratedTable table(tf);
  const PreintegralTables t = table.tables();
  std::mt19937 random(13);
  std::uniform_real_distribution<float> scalar(-0.2f, 1.2f), hair(-2e-6f, 2e-6f);
  int opaque = 0, visible = 0, narrow = 0;
  for (int round = 0; round < 4000; ++round) {
    alignas(32) float ends[9];
    ends[0] = scalar(random);
    for (int j = 1; j < 9; ++j) {
      const int kind = int(random() % 3);
      ends[j] = kind == 0 ? ends[j - 1] : kind == 1 ? ends[j - 1] + hair(random) : scalar(random);
    }
    for (double length : {0.3, 2.0}) {
      const preint::Ends8 backs = preint::endsAt(t, _mm256_loadu_ps(ends + 1));
      preint::StoredEnds before;
      preint::store(preint::endAt(t, ends[0]), before);
      const preint::Ends8 fronts = preint::fronts(before, backs);
      const preint::Segments8 lanes = preint::segments<true>(fronts, backs, length);
      alignas(64) double r[8], g[8], b[8], a[8], centre[8];
      _mm512_store_pd(r, lanes.r);
      _mm512_store_pd(g, lanes.g);
      _mm512_store_pd(b, lanes.b);
      _mm512_store_pd(a, lanes.a);
      _mm512_store_pd(centre, lanes.centre);
      for (int j = 0; j < 8; ++j) {
        float expectedCentre = -1;
        const preint::End front = preint::endAt(t, ends[j]), back = preint::endAt(t, ends[j + 1]);
        const Rgba expected = preint::segment(t, front, back, length, &expectedCentre);
        // segment()'s test for an opaque segment.
        const bool expectOpaque = (std::abs(back.x - front.x) > preint::kMinSpan && back.O != front.O) ||
                                  front.opaque > 0 || back.opaque > 0;
        const bool isOpaque = (lanes.opaque >> j) & 1;
        INFO("segment " << ends[j] << " to " << ends[j + 1] << ", length " << length);
        CHECK(isOpaque == expectOpaque);
        if (isOpaque) {
          ++opaque;
          continue;
        }
        narrow += std::abs(double(ends[j + 1]) - double(ends[j])) * t.scale <= preint::kMinSpan;
        visible += a[j] > 0;
        CHECK(std::abs(float(r[j]) - expected.r) <= 1e-7);
        CHECK(std::abs(float(g[j]) - expected.g) <= 1e-7);
        CHECK(std::abs(float(b[j]) - expected.b) <= 1e-7);
        CHECK(std::abs(float(a[j]) - expected.a) <= 1e-7);
        if (a[j] > 0) CHECK(std::abs(float(centre[j]) - expectedCentre) <= 1e-6);
      }
    }
  }
  // Every kind of lane was met.
  CHECK(opaque > 1000);
  CHECK(visible > 10000);
  CHECK(narrow > 5000);
}

// Identity: the rows look-up (spansAt(), PreintegralRows: one row per end,
// the differences and sums of consecutive rows, one transpose), which the
// unshaded batch takes through a table without opaque nodes, gives the
// cells look-up's segments (endsAt(), fronts(), segments()), batch after
// batch with the last end carried, and from a front looked up alone
// (rowEnd()): the same operations on the same doubles, so equal bit for
// bit but where the compiler fuses a multiply and an add in one and not
// in the other (an ulp, in about one segment in 10^4 here; bound 1e-12
// relative, and at most one in a thousand not bit-equal). A field in the
// wrong lane of a row, a slope not halved, the wrong sign between rows or
// a carried end off by a lane changes colours or opacities by far more. Scalars are drawn
// across the control points and beyond them, with ends equal, a hair
// apart (below preint::kMinSpan) and far apart.
TEST_CASE("the rows look-up of pre-integrated segments equals the cells look-up", "[preintegration]") {
  TransferFunctionSpec tf = mixedTransfer();
  CHECK(PreintegratedTable(tf).tables().opaqueNodes);
  for (auto& point : tf.points)
    if (point.opacity >= 1) point.opacity = 0.9;
  const PreintegratedTable table(tf);
  const PreintegralTables t = table.tables();
  REQUIRE_FALSE(t.opaqueNodes);
  std::mt19937 random(17);
  std::uniform_real_distribution<float> scalar(-0.2f, 1.2f), hair(-2e-6f, 2e-6f);
  int visible = 0, narrow = 0, compared = 0, unequal = 0;
  for (int round = 0; round < 500; ++round) {
    std::vector<float> ends(1 + 8 * 4);
    ends[0] = scalar(random);
    for (std::size_t j = 1; j < ends.size(); ++j) {
      const int kind = int(random() % 3);
      ends[j] = kind == 0 ? ends[j - 1] : kind == 1 ? ends[j - 1] + hair(random) : scalar(random);
    }
    // The first front as the lanes compute it (endAt(), one at a time, may
    // round an end's integrals otherwise, by fused multiply-adds).
    preint::StoredEnds before;
    preint::store(preint::endsAt(t, _mm256_set1_ps(ends[0])), before);
    preint::RowEnd beforeRow = preint::rowEnd(t, ends[0]);
    for (std::size_t batch = 0; batch + 1 < ends.size(); batch += 8) {
      const __m256 backScalars = _mm256_loadu_ps(&ends[batch + 1]);
      const preint::Ends8 backs = preint::endsAt(t, backScalars);
      const preint::Segments8 cells = preint::segments<false>(preint::fronts(before, backs), backs, 0.7);
      preint::store(backs, before);
      const preint::Segments8 rows = preint::integrate<false>(preint::spansAt(t, backScalars, beforeRow), 0.7);
      alignas(64) double expected[4][8], got[4][8];
      const __m512d e[4] = {cells.r, cells.g, cells.b, cells.a}, g[4] = {rows.r, rows.g, rows.b, rows.a};
      for (int c = 0; c < 4; ++c) {
        _mm512_store_pd(expected[c], e[c]);
        _mm512_store_pd(got[c], g[c]);
      }
      CHECK(rows.opaque == 0);
      CHECK(cells.opaque == 0);
      for (int j = 0; j < 8; ++j) {
        INFO("segment " << ends[batch + j] << " to " << ends[batch + j + 1]);
        for (int c = 0; c < 4; ++c) {
          INFO("channel " << c << std::hexfloat << " " << got[c][j] << " " << expected[c][j]);
          CHECK(std::abs(got[c][j] - expected[c][j]) <= 1e-12 * std::abs(expected[c][j]));
          unequal += got[c][j] != expected[c][j];
        }
        visible += expected[3][j] > 0;
        narrow += std::abs(double(ends[batch + j + 1]) - double(ends[batch + j])) * t.scale <= preint::kMinSpan;
        ++compared;
      }
    }
  }
  INFO(compared << " segments, " << visible << " visible, " << narrow << " narrow");
  CHECK(visible > 5000);
  CHECK(narrow > 3000);
  CHECK(unequal <= compared / 1000);
}
#endif

#ifdef PVR_HAVE_BATCH_KERNEL
// Identity: the batched pre-integrated kernel composites the segments the
// one-at-a-time loop does, in the same order, through a volume whose
// scalars cross opacity 1, an empty range (whole batches of empty cells)
// and the clamped ends of the transfer function, with a slab of NaN voxels,
// for runs of every length from 1 to 40 segments (partial batches); they
// differ in how positions and interpolations round (fused multiply-adds),
// 1e-5 at most.
TEST_CASE("the batched pre-integrated kernel equals the scalar kernel through opaque and empty cells and NaN voxels",
          "[preintegration]") {
  const GridGeometry grid = cubeGrid(48);
  auto field = [](Vec3 q) {
    if (q.x >= 30 && q.x <= 31) return double(NAN);
    return 0.5 + 0.7 * std::sin(q.x * 0.21) * std::cos(q.y * 0.13 + q.z * 0.07);
  };
  const Brick volume = makeVolume(grid, ScalarType::kFloat32, field);
  const TransferFunctionSpec tf = mixedTransfer();
  const Vec3 c = grid.center();
  const Camera camera = makeCamera(Projection::kPerspective, c - normalize(Vec3{1, 0.35, 0.2}) * 80.0, c,
                                   {0, 0, 1}, 40, 16, 16);
  for (bool shaded : {false, true}) {
    const RenderOptions o = makeOptions(0.7, true, shaded);
    const PreintegratedKernel setup(volume, tf, o);
    const KernelParams& p = setup.params();
    REQUIRE(p.indices32);
    double worst = 0;
    int runs = 0;
    setup.forEachRay(camera, grid, o.step, [&](const RaySetup& ray, std::int64_t first, std::int64_t last) {
      for (std::int64_t length = 1; length <= 40 && first + 1 + length <= last; length += 3) {
        const std::int64_t from = first + 1, to = from + length;
        kernel::Accumulator scalar, batched;
        std::uint64_t n1 = 0, n2 = 0;
        auto run = [&](auto kernelShaded) {
          constexpr bool kShaded = decltype(kernelShaded)::value;
          kernel::runScalar<float, kShaded, true>(p, ray, from, to, scalar, n1);
          std::int64_t start = from;
          kernel::runBatchedPreintegrated<float, kShaded>(p, ray, start, to, batched, n2);
          kernel::runScalar<float, kShaded, true>(p, ray, start, to, batched, n2);
        };
        if (shaded) run(std::true_type{});
        else run(std::false_type{});
        // Early termination (an opaque segment) stops the scalar loop at
        // its segment and the batch at the end of its batch.
        if (!(scalar.a >= p.earlyTermination)) REQUIRE(n1 == n2);
        worst = std::max({worst, std::abs(scalar.r - batched.r), std::abs(scalar.g - batched.g),
                          std::abs(scalar.b - batched.b), std::abs(scalar.a - batched.a)});
        ++runs;
      }
    });
    INFO((shaded ? "shaded" : "unshaded") << ": " << runs << " runs, max difference " << worst);
    CHECK(runs > 500);
    CHECK(worst < 1e-5);
  }
}
#endif

}  // namespace pvr::core
