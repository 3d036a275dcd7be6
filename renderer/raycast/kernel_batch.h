// Eight consecutive samples of one ray per step, AVX2 arithmetic.
//
// The scalar loop spends most of its ~100 instructions a sample on
// position, cell, fraction, index and interpolation arithmetic that does
// not depend on the other samples; here eight samples share each of those
// instructions. Float voxels are fetched with scalar loads (hardware
// gathers were measured at ~19 cycles each, slower than loads); integer
// voxels with one 32-bit gather per corner pair, which beat eight loads
// and inserts on the peer scene (batch_loads.h). Plain
// classification and compositing take the eight samples together as well
// (kernel_batch_over.h), and so do the pre-integrated batch's eight
// segments, lit (shade_lanes.h) eight at a time, unless one is opaque: then
// they are composited one at a time, in the scalar loop's order and precision.
#pragma once

#if defined(__AVX2__) && defined(__FMA__)
#define PVR_HAVE_BATCH_KERNEL 1

#include <immintrin.h>

#include <cstdint>
#include <cstring>
#include <type_traits>
#include <utility>

#include "kernel.h"
#include "preint_lanes.h"
#include "preint_lighting.h"
#include "kernel_batch_over.h"
#include "batch_loads.h"
#include "shade_lanes.h"

namespace pvr::core::kernel {

// No chunk follows on (runBatched).
struct NoFollowOn {
  std::int64_t operator()(std::int64_t at) const { return at; }
};

// Samples [start, exit) of a visible run, eight at a time, the last 1 to 7
// as one batch with the lanes past `exit` masked out; `start` advances past
// what was done (to `exit` unless the ray terminated). Plain (not
// pre-integrated) classification; needs voxel indices that fit 32 bits
// (KernelParams::indices32). A batch whose eight table coordinates all lie
// in the transfer function's transparent ends (KernelParams::clearBelow,
// clearAbove) stops after the reconstruction; the others are classified
// and composited with each other first, then into the ray
// (kernel_batch_over.h). Returns true when the ray reached the
// early-termination opacity, tested after each batch. kPower: how shading
// raises nh^shininess (specular_power.h).
//
// `more` (from runSpan, cast_ray.h) lets a walk's next chunk follow on: when
// the whole batches end exactly at `exit`, more(exit) is where the batches
// may go on to (exit itself: nowhere), and the loop goes on there as a new
// call from `exit` would, with the same batches and so the same bits.
//
// kShifted: voxel indices by shifts (KernelParams::strideShift, voxelIndex8);
// runBatched picks it per call.
template <typename T, bool kShaded, int kPower, bool kShifted, typename More>
inline bool runBatchedIndexed(const KernelParams& p, const RaySetup& ray, std::int64_t& start,
                              std::int64_t exit, Accumulator& acc, std::uint64_t& samples, More&& more) {
  if (start >= exit) return false;
  const T* v = static_cast<const T*>(p.voxels);
  const float o[3] = {float(ray.origin[0]), float(ray.origin[1]), float(ray.origin[2])};
  const float d[3] = {float(ray.step[0]), float(ray.step[1]), float(ray.step[2])};
  const __m256 o0 = _mm256_set1_ps(o[0]), o1 = _mm256_set1_ps(o[1]), o2 = _mm256_set1_ps(o[2]);
  const __m256 d0 = _mm256_set1_ps(d[0]), d1 = _mm256_set1_ps(d[1]), d2 = _mm256_set1_ps(d[2]);
  const __m256 lanes = _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7);
  const IndexLanes<kShifted> indexing(p);
  const __m256 scale = _mm256_set1_ps(p.tableScale), offset = _mm256_set1_ps(p.tableOffset);
  const __m256 tableLast = _mm256_set1_ps(float(p.tableEntries - 1));
  const __m256i entryLast = _mm256_set1_epi32(p.tableEntries - 2);
  const __m256 clearBelow = _mm256_set1_ps(p.clearBelow), clearAbove = _mm256_set1_ps(p.clearAbove);
  const std::int64_t sy = p.strideY, sz = p.strideZ;
  __m256d gathered = _mm256_setr_pd(acc.r, acc.g, acc.b, acc.a);
  bool terminated = false;

  // Positions and reconstructed values of samples s .. s+7; or, where all
  // eight lie in clear cells (p.clearCells), `clear` and no value.
  struct Batch {
    __m256 u[3];
    __m256 value;
    bool clear;
  };
  const std::uint8_t* clearCells = p.clearCells;
  auto reconstruct = [&](std::int64_t s) __attribute__((always_inline)) {
    Batch out;
    const __m256 k = _mm256_add_ps(_mm256_set1_ps(float(s)), lanes);
    const __m256 u0 = _mm256_fmadd_ps(k, d0, o0), u1 = _mm256_fmadd_ps(k, d1, o1),
                 u2 = _mm256_fmadd_ps(k, d2, o2);
    const __m256i i = clampCells8(u0, p.ownCellLo[0], p.ownCellHi[0]);
    const __m256i j = clampCells8(u1, p.ownCellLo[1], p.ownCellHi[1]);
    const __m256i kk = clampCells8(u2, p.ownCellLo[2], p.ownCellHi[2]);
    const __m256 fx = _mm256_sub_ps(u0, _mm256_cvtepi32_ps(i));
    const __m256 fy = _mm256_sub_ps(u1, _mm256_cvtepi32_ps(j));
    const __m256 fz = _mm256_sub_ps(u2, _mm256_cvtepi32_ps(kk));
    const __m256i voxelIndex = voxelIndex8(indexing, i, j, kk);
    alignas(32) std::int32_t index[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(index), voxelIndex);
    out.u[0] = u0;
    out.u[1] = u1;
    out.u[2] = u2;
    // A batch in clear cells reads no voxel (clear_cells.h): 31 % of the
    // peer scene's batches, 46 % of the CT head's; 2-5 % less CPU a frame,
    // as the bitmap's own eight loads a batch take back most of the reads
    // saved (bench/results/plain.txt, section 10).
    out.clear = clearCells && allCellsClear8(clearCells, voxelIndex);
    if (out.clear) return out;
    // Trilinear reconstruction.
    __m256 a0, a1, b0, b1, c0, c1, e0, e1;
    loadPairs8(v, index, 0, a0, a1);
    loadPairs8(v, index, sy, b0, b1);
    loadPairs8(v, index, sz, c0, c1);
    loadPairs8(v, index, sy + sz, e0, e1);
    out.value = lerp8(lerp8(lerp8(a0, a1, fx), lerp8(b0, b1, fx), fy),
                      lerp8(lerp8(c0, c1, fx), lerp8(e0, e1, fx), fy), fz);
    return out;
  };
  // Classify, light and composite one batch into `gathered`; true when the
  // ray reached the early-termination opacity. A tail batch (kTail) keeps
  // only the lanes in `inRun`: the others lie past the run, their
  // positions' cells clamped into the owned box as every lane's are (so
  // their reads stay in bounds), and are made transparent as non-finite
  // values are, before lighting (which lights only lanes with opacity).
  auto take = [&](const Batch& batch, auto kTail, [[maybe_unused]] __m256 inRun)
                  __attribute__((always_inline)) -> bool {
    if (batch.clear) return false;
    const __m256 value = batch.value;
    // Table coordinates (a NaN becomes 0: max returns its second operand).
    const __m256 x = _mm256_min_ps(
        _mm256_max_ps(_mm256_fmadd_ps(value, scale, offset), _mm256_setzero_ps()), tableLast);
    // Lanes that classify as transparent; a non-finite value is one of them.
    __m256 clear = _mm256_or_ps(_mm256_cmp_ps(x, clearBelow, _CMP_LT_OQ), _mm256_cmp_ps(x, clearAbove, _CMP_GE_OQ));
    __m256 keep = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
    if constexpr (std::is_floating_point_v<T>) {
      const __m256 magnitude = _mm256_andnot_ps(_mm256_set1_ps(-0.0f), value);
      keep = _mm256_cmp_ps(magnitude, _mm256_set1_ps(FLT_MAX), _CMP_LE_OQ);
    }
    if constexpr (decltype(kTail)::value) keep = _mm256_and_ps(keep, inRun);
    constexpr bool kMasked = std::is_floating_point_v<T> || decltype(kTail)::value;
    if constexpr (kMasked) clear = _mm256_or_ps(clear, _mm256_andnot_ps(keep, _mm256_castsi256_ps(_mm256_set1_epi32(-1))));
    if (_mm256_movemask_ps(clear) == 0xFF) return false;
    // Classify.
    const __m256i entry = _mm256_min_epi32(_mm256_cvttps_epi32(x), entryLast);
    Quads c = classifyQuads(p.table, entry, _mm256_sub_ps(x, _mm256_cvtepi32_ps(entry)));
    if constexpr (kMasked) keepQuads(c, keep);
    if constexpr (kShaded) {
      // Light the visible samples, all eight lanes at once (shade_lanes.h).
      shadeQuads<T, kPower, kShifted>(v, p, ray, batch.u, c);
    }
    // Composite the batch, then the batch into the ray.
    gathered = addBehind4(gathered, overQuads(c));
    return _mm256_cvtsd_f64(_mm256_permute4x64_pd(gathered, 0xFF)) >= p.earlyTermination;
  };
  // The next batch's voxels are fetched before this batch's transparency
  // test: a mispredicted skip then no longer discards the fetch in flight
  // (peer scene: 15 % less CPU time, bench/results/plain.txt). Fetched only
  // while samples of the run remain (the tail's too: its lanes past the run
  // read clamped cells), so nothing outside the owned cells is read; the
  // batch fetched ahead of one that terminates the ray is dropped.
  Batch next = reconstruct(start);
  for (std::int64_t s = start; s + 8 <= exit; s += 8, start = s) {
    const Batch batch = next;
    if (s + 8 == exit) exit = more(exit);
    if (s + 8 < exit) next = reconstruct(s + 8);
    samples += 8;
    if (take(batch, std::false_type{}, __m256{})) {
      start = s + 8;
      terminated = true;
      break;
    }
  }
  // The run's last 1 to 7 samples, as one more batch with the lanes past
  // the run masked out. One at a time (runScalar), each visible sample lit
  // by the scalar gradient, they took 2.6 % of a shaded CT head frame for
  // 1.2 % of its samples; as a batch, the frame takes 1.5-2 % less CPU
  // (unshaded ~3 %; bench/results/shade.txt, session 11). Composited
  // in float like any batch: within a few ulp of the batch's colour of the
  // scalar loop's double "over" (kernel_batch_over.h), and early
  // termination is tested after it, as after every batch.
  if (!terminated && start < exit) {
    const int count = int(exit - start);
    samples += std::uint64_t(count);
    terminated = take(next, std::true_type{}, _mm256_cmp_ps(lanes, _mm256_set1_ps(float(count)), _CMP_LT_OQ));
    start = exit;
  }
  alignas(32) double out[4];
  _mm256_store_pd(out, gathered);
  acc.r = out[0];
  acc.g = out[1];
  acc.b = out[2];
  acc.a = out[3];
  return terminated;
}

template <typename T, bool kShaded, int kPower = kTablePower, typename More = NoFollowOn>
inline bool runBatched(const KernelParams& p, const RaySetup& ray, std::int64_t& start, std::int64_t exit,
                       Accumulator& acc, std::uint64_t& samples, More&& more = More{}) {
  if (p.strideShift[0] >= 0)
    return runBatchedIndexed<T, kShaded, kPower, true>(p, ray, start, exit, acc, samples, std::forward<More>(more));
  return runBatchedIndexed<T, kShaded, kPower, false>(p, ray, start, exit, acc, samples, std::forward<More>(more));
}

// The voxel indices of the cells of samples [first, first + 8) as `around`
// finds them (positions clamped into the domain, cells into the stored
// box: a pre-integrated segment's ends may lie beyond the owned box), and
// the positions' fractions in them (f).
template <bool kShifted = false>
[[gnu::always_inline]] inline __m256i aroundCells8(const KernelParams& p, const __m256 o[3], const __m256 d[3],
                                                   std::int64_t first, __m256 f[3]) {
  const __m256 k = _mm256_add_ps(_mm256_set1_ps(float(first)), _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7));
  __m256i cell[3];
  for (int a = 0; a < 3; ++a) {
    const __m256 u = _mm256_min_ps(_mm256_max_ps(_mm256_fmadd_ps(k, d[a], o[a]), _mm256_setzero_ps()),
                                   _mm256_set1_ps(p.domainMax[a]));
    cell[a] = clampCells8(u, p.storedCellLo[a], p.storedCellHi[a]);
    f[a] = _mm256_sub_ps(u, _mm256_cvtepi32_ps(cell[a]));
  }
  return voxelIndex8(IndexLanes<kShifted>(p), cell[0], cell[1], cell[2]);
}

// The scalars at samples [first, first + 8) as `around` reads them
// (aroundCells8); `lo` and `hi` get the ranges of their cells' nodes
// (aroundRange()).
template <typename T, bool kShifted = false>
[[gnu::always_inline]] inline __m256 aroundBatch(const T* v, const KernelParams& p, const __m256 o[3],
                                                 const __m256 d[3], std::int64_t first, __m256& lo,
                                                 __m256& hi) {
  __m256 f[3];
  alignas(32) std::int32_t index[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(index), aroundCells8<kShifted>(p, o, d, first, f));
  __m256 a0, a1, b0, b1, c0, c1, e0, e1;
  loadPairs8(v, index, 0, a0, a1);
  loadPairs8(v, index, p.strideY, b0, b1);
  loadPairs8(v, index, p.strideZ, c0, c1);
  loadPairs8(v, index, p.strideY + p.strideZ, e0, e1);
  lo = _mm256_min_ps(_mm256_min_ps(_mm256_min_ps(a0, a1), _mm256_min_ps(b0, b1)),
                     _mm256_min_ps(_mm256_min_ps(c0, c1), _mm256_min_ps(e0, e1)));
  hi = _mm256_max_ps(_mm256_max_ps(_mm256_max_ps(a0, a1), _mm256_max_ps(b0, b1)),
                     _mm256_max_ps(_mm256_max_ps(c0, c1), _mm256_max_ps(e0, e1)));
  return lerp8(lerp8(lerp8(a0, a1, f[0]), lerp8(b0, b1, f[0]), f[1]),
               lerp8(lerp8(c0, c1, f[0]), lerp8(e0, e1, f[0]), f[1]), f[2]);
}

#ifdef PVR_HAVE_PREINT_LANES
// The colours of eight segments as Quads (kernel_batch_over.h), lanes
// outside `keep` transparent: r, g, b, a of lanes j and j + 4 side by side.
[[gnu::always_inline]] inline Quads segmentQuads(const preint::Segments8& seg, __mmask8 keep) {
  const __m256 r = _mm512_maskz_cvtpd_ps(keep, seg.r), g = _mm512_maskz_cvtpd_ps(keep, seg.g);
  const __m256 b = _mm512_maskz_cvtpd_ps(keep, seg.b), a = _mm512_maskz_cvtpd_ps(keep, seg.a);
  const __m256 rgLow = _mm256_unpacklo_ps(r, g), baLow = _mm256_unpacklo_ps(b, a);  // lanes 0 1 | 4 5
  const __m256 rgHigh = _mm256_unpackhi_ps(r, g), baHigh = _mm256_unpackhi_ps(b, a);  // lanes 2 3 | 6 7
  Quads q;
  q.q[0] = _mm256_shuffle_ps(rgLow, baLow, 0x44);
  q.q[1] = _mm256_shuffle_ps(rgLow, baLow, 0xEE);
  q.q[2] = _mm256_shuffle_ps(rgHigh, baHigh, 0x44);
  q.q[3] = _mm256_shuffle_ps(rgHigh, baHigh, 0xEE);
  return q;
}

// Where shadeSegment() lights segments [s + j, s + j + 1), j = 0..7: the
// points centre - spread and centre + spread of each (clamped into the
// segment), as index-space positions u[0] (front) and u[1] (back), the
// position formula of shadeSegment() with fused multiply-adds.
[[gnu::always_inline]] inline void litPoints8(const __m256 o[3], const __m256 d[3],
                                              std::int64_t s, const preint::Segments8& seg, __m256 u[2][3]) {
  const __m256 centre = _mm512_maskz_cvtpd_ps(preint::kAll, seg.centre);
  const __m256 spread = _mm512_maskz_cvtpd_ps(preint::kAll, seg.spread);
  const __m256 lane = _mm256_add_ps(_mm256_set1_ps(float(s)), _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7));
  const __m256 t[2] = {
      _mm256_add_ps(lane, _mm256_max_ps(_mm256_sub_ps(centre, spread), _mm256_setzero_ps())),
      _mm256_add_ps(lane, _mm256_min_ps(_mm256_add_ps(centre, spread), _mm256_set1_ps(1.0f)))};
  for (int e = 0; e < 2; ++e)
    for (int a = 0; a < 3; ++a) u[e][a] = _mm256_fmadd_ps(t[e], d[a], o[a]);
}
#endif

// Pre-integrated segments [s, s + 1) for s in [start, exit), eight at a
// time: the scalars at s + 2 .. s + 9 in one batch, the eight corrected
// nodes s + 1 .. s + 8 (curvedNode()) in another, the eight segments
// (preint_lanes.h) and the "over" per segment in order. With AVX-512 the
// last batch may be partial (its lanes beyond `exit` read clamped positions
// and are not composited) and `start` ends at `exit`; without, the
// segments are integrated per lane, eight at a time while eight remain, and
// the caller takes the rest one at a time. `start` advances past what was
// done. Returns true at the early-termination opacity. kShifted: voxel
// indices by shifts (voxelIndex8); runBatchedPreintegrated picks it.
//
// `more`, as runBatched's, lets a walk's next chunk follow on: when this
// batch reaches `exit` (full or, with AVX-512, partial), more(exit) is
// where the segments may go on to, and the loop goes on as one call over
// both chunks would. Each call began with a window of its own (a ninth
// reconstruction for a chunk's 32 segments, and a front end looked up
// again): peer scene unshaded, 7 % less CPU a frame
// (bench/results/preintegration.txt). Only the grouping of the segments
// into batches changes, and with it the images' last bit.
template <typename T, bool kShaded, bool kShifted, typename More>
inline bool runPreintegratedIndexed(const KernelParams& p, const RaySetup& ray, std::int64_t& start,
                                    std::int64_t exit, Accumulator& acc, std::uint64_t& samples, More&& more) {
#ifdef PVR_HAVE_PREINT_LANES
  constexpr std::int64_t kFullBatchesOnly = 0;
#else
  constexpr std::int64_t kFullBatchesOnly = 7;
#endif
  if (start + kFullBatchesOnly >= exit) return false;
  const T* v = static_cast<const T*>(p.voxels);
  const __m256 o[3] = {_mm256_set1_ps(float(ray.origin[0])), _mm256_set1_ps(float(ray.origin[1])),
                       _mm256_set1_ps(float(ray.origin[2]))};
  const __m256 d[3] = {_mm256_set1_ps(float(ray.step[0])), _mm256_set1_ps(float(ray.step[1])),
                       _mm256_set1_ps(float(ray.step[2]))};
  const __m256 finiteMax = _mm256_set1_ps(FLT_MAX), signBit = _mm256_set1_ps(-0.0f);
  auto finite8 = [&](__m256 x) __attribute__((always_inline)) {
    return _mm256_cmp_ps(_mm256_andnot_ps(signBit, x), finiteMax, _CMP_LE_OQ);
  };
  // The window of samples in registers (through memory, the loads of a
  // batch's samples shifted by one and two lanes straddled the store just
  // made and stalled store forwarding): lanes 6 and 7 of `carried` hold the
  // samples at s and s + 1, lane 7 of carriedLo and carriedHi the range of
  // the cell of s + 1 (aroundRange()).
  __m256 carried, carriedLo, carriedHi;
  // Lane j of the result: lane 6 + j (`bytes` 8) or 7 + j (`bytes` 12) of
  // `window` followed by `x`, a shift across the two vectors.
  auto shifted = [](__m256 window, __m256 x, auto bytes) __attribute__((always_inline)) {
    const __m256i t = _mm256_castps_si256(_mm256_permute2f128_ps(window, x, 0x21));
    return _mm256_castsi256_ps(_mm256_alignr_epi8(_mm256_castps_si256(x), t, decltype(bytes)::value));
  };
  using kOne = std::integral_constant<int, 12>;  // one sample before x's lanes
  using kTwo = std::integral_constant<int, 8>;   // two samples before
  // The window at sample `at` (preintWindow()), as a call from `at` opens
  // it: the samples at at - 1 .. at + 6 in one batch; the sample at at + 1
  // and its range carried for the first batch's first node. Returns the
  // front node at `at`.
  auto openWindow = [&](std::int64_t at) __attribute__((always_inline)) {
    alignas(32) float first[8], firstLo[8], firstHi[8];
    __m256 lo8, hi8;
    _mm256_store_ps(first, aroundBatch<T, kShifted>(v, p, o, d, at - 1, lo8, hi8));
    _mm256_store_ps(firstLo, lo8);
    _mm256_store_ps(firstHi, hi8);
    float front = curvedNode<T>(first[0], first[1], first[2], firstLo[1], firstHi[1]);
    if (!finite<T>(front)) front = 0;  // looked up as 0 (segmentEnd())
    carried = _mm256_set_ps(first[2], first[1], 0, 0, 0, 0, 0, 0);
    carriedLo = _mm256_set1_ps(firstLo[2]);
    carriedHi = _mm256_set1_ps(firstHi[2]);
    return front;
  };
  const float frontScalar = openWindow(start);
#ifndef PVR_HAVE_PREINT_LANES
  preint::End frontEnd = preint::endAt(p.preint, frontScalar);
#endif
  // On to the next batch, `count` segments done: the two samples before
  // its first node carried over.
  auto advance = [&](std::int64_t s, int count, __m256 x, __m256 xLo, __m256 xHi) __attribute__((always_inline)) {
    carried = x;
    carriedLo = xLo;
    carriedHi = xHi;
    samples += std::uint64_t(count);
    start = s + count;
  };
#ifdef PVR_HAVE_PREINT_LANES
  // Lane 7 of `before`: the next segment's front end, at node frontNode
  // (stale after a batch of empty cells, and before the first batch).
  // Unshaded through a table without opaque nodes, the rows look-up
  // (preint_lanes.h spansAt()) with one row of the last end carried
  // (beforeRow); else the cells' (endsAt()).
  preint::StoredEnds before;
  preint::RowEnd beforeRow;
  float frontNode = frontScalar;
  bool frontStale = true;  // looked up by the first batch that needs it
  using Rows = std::true_type;
  // A batch whose front node and eight nodes all lie in clear cells of
  // the segments' end (p.clearCells, ClearEnds::ofSegments) integrates
  // nothing, as allClear() would find; it is known from the batch before
  // (its last node, the front, and the next eight samples' cells) and then
  // skipped before its samples are read: the peer scene's unshaded frame
  // took 10 % less CPU (bench/results/preintegration.txt). The window
  // reopens at the next batch that is not skipped, as a call from there
  // would open it (the same samples and nodes, so the same bits).
  const std::uint8_t* clearCells = std::is_floating_point_v<T> ? nullptr : p.clearCells;
  const EmptyEnd clearEnd = segmentsClearEnd(p.preint);
  // The cells of samples first .. first + 7 (as aroundBatch() finds them) all clear.
  auto cellsClear = [&](std::int64_t first) __attribute__((always_inline)) {
    __m256 f[3];
    return allCellsClear8(clearCells, aroundCells8<kShifted>(p, o, d, first, f));
  };
#endif
  using Cells = std::false_type;
  // The batches, with rows or cells (two loops, the choice made once).
  auto batches = [&](auto lookUp) __attribute__((always_inline)) -> bool {
    [[maybe_unused]] constexpr bool kRows = decltype(lookUp)::value;  // (AVX-512 only)
    // The next batch's samples are fetched before this batch's empty test,
    // as runBatched() does (a mispredicted skip then no longer discards the
    // loads in flight); only when a next batch will run, and dropped when
    // the ray terminates. aroundBatch() clamps its positions, so a batch
    // past `exit` would read inside the stored box as well.
    __m256 nextLo, nextHi;
    __m256 nextAfter = aroundBatch<T, kShifted>(v, p, o, d, start + 2, nextLo, nextHi);
#ifdef PVR_HAVE_PREINT_LANES
    bool skip = false;  // batch s lies in clear cells: its samples were not read
#endif
    for (std::int64_t s = start; s + kFullBatchesOnly < exit; s += 8) {
#ifdef PVR_HAVE_PREINT_LANES
      if (skip) {
        if (s + 8 >= exit) exit = more(exit);
        const int count = int(std::min<std::int64_t>(8, exit - s));
        samples += std::uint64_t(count);
        start = s + count;
        frontStale = true;
        // Its last node, the next batch's front, lies in a clear cell too.
        skip = s + 8 < exit && cellsClear(s + 9);
        if (!skip && s + 8 < exit) {
          frontNode = openWindow(s + 8);
          nextAfter = aroundBatch<T, kShifted>(v, p, o, d, s + 10, nextLo, nextHi);
        }
        continue;
      }
#endif
      // The samples at s + 2 .. s + 9 (after), and at s .. s + 7 and s + 1 .. s + 8.
      const __m256 after = nextAfter, lo8 = nextLo, hi8 = nextHi;
      if (s + 8 >= exit) exit = more(exit);
      const __m256 before8 = shifted(carried, after, kTwo{}), at = shifted(carried, after, kOne{});
      const __m256 bend = _mm256_add_ps(_mm256_sub_ps(before8, _mm256_add_ps(at, at)), after);
      __m256 node = _mm256_sub_ps(at, _mm256_mul_ps(bend, _mm256_set1_ps(1.0f / 12.0f)));
      const __m256 clamped = _mm256_min_ps(_mm256_max_ps(node, shifted(carriedLo, lo8, kOne{})),
                                           shifted(carriedHi, hi8, kOne{}));
      if constexpr (std::is_floating_point_v<T>) {
        node = _mm256_blendv_ps(at, clamped, finite8(node));
      } else {
        node = clamped;
      }
      const int count = int(std::min<std::int64_t>(8, exit - s));  // segments of this batch
#ifdef PVR_HAVE_PREINT_LANES
      // A segment with a non-finite sample at an end is empty; its node is
      // looked up as 0 (segmentEnd()).
      unsigned valid = (1u << count) - 1;
      if constexpr (std::is_floating_point_v<T>) {
        node = _mm256_and_ps(node, finite8(node));
        valid &= unsigned(_mm256_movemask_ps(_mm256_and_ps(finite8(before8), finite8(at))));
      }
      // The next batch: skipped (its front is this batch's last node; the
      // cells are read only after a clear front), or its samples fetched
      // before this batch's empty test.
      const float nextFront = _mm256_cvtss_f32(_mm256_permutevar8x32_ps(node, _mm256_set1_epi32(7)));
      skip = clearCells && s + 8 < exit && emptyEndOf(p.preint, nextFront) == clearEnd && cellsClear(s + 9);
      if (!skip && s + 8 < exit) nextAfter = aroundBatch<T, kShifted>(v, p, o, d, s + 10, nextLo, nextHi);
      // A batch whose nodes all lie in empty cells integrates nothing: skip
      // the table, count the samples; the front end is looked up again only
      // when a batch needs it.
      if (preint::allClear(p.preint, node, frontNode) ||
          (p.preint.gaps && preint::allEmpty(p.preint, node, frontNode))) {
        frontStale = true;
        frontNode = nextFront;
        advance(s, count, after, lo8, hi8);
        continue;
      }
      if (frontStale) {
        if constexpr (kRows) beforeRow = preint::frontRow(p.preint, frontNode);
        else preint::store(preint::endAt(p.preint, frontNode), before);
      }
      frontStale = false;
      frontNode = nextFront;
      preint::Segments8 seg;
      alignas(64) double frontX[8], backX[8];  // of opaque segments
      if constexpr (kRows) {
        seg = preint::integrate<false>(preint::spansAt(p.preint, node, beforeRow), p.stepLength);
      } else {
        const preint::Ends8 backs = preint::endsAt(p.preint, node);
        const preint::Ends8 fronts = preint::fronts(before, backs);
        seg = preint::segments<kShaded>(fronts, backs, p.stepLength);
        preint::store(backs, before);
        if (seg.opaque) {
          _mm512_store_pd(backX, backs.x);
          _mm512_store_pd(frontX, fronts.x);
        }
      }
      if (!seg.opaque) {
        // With no opaque segment (those take the loop below), the eight
        // segments are composited with each other as plain samples are
        // (kernel_batch_over.h), then into the ray: one link of the "over"
        // chain per batch instead of eight.
        Quads batch = segmentQuads(seg, __mmask8(valid));
        if constexpr (kShaded) {
          // Lit: the eight segments' two lighting points (shadeSegment()) lit
          // as two batches of eight samples (shade_lanes.h) and the two
          // colours averaged (the opacities are the unlit ones in both, so
          // stay exact). (Lit one lane at a time, each point's gradient reading
          // its 32 nodes with scalar loads, lighting took about 40 % of a
          // shaded frame.)
          __m256 u[2][3];
          litPoints8(o, d, s, seg, u);
          Quads back = batch;
          shadeQuads<T, kTablePower, kShifted>(v, p, ray, u[0], batch);
          shadeQuads<T, kTablePower, kShifted>(v, p, ray, u[1], back);
          for (int j = 0; j < 4; ++j)
            batch.q[j] = _mm256_mul_ps(_mm256_add_ps(batch.q[j], back.q[j]), _mm256_set1_ps(0.5f));
        }
        __m256d gathered = _mm256_setr_pd(acc.r, acc.g, acc.b, acc.a);
        gathered = addBehind4(gathered, overQuads(batch));
        alignas(32) double out[4];
        _mm256_store_pd(out, gathered);
        acc = {out[0], out[1], out[2], out[3]};
        advance(s, count, after, lo8, hi8);
        if (acc.a >= p.earlyTermination) return true;
        continue;
      }
      alignas(32) float r[8], g[8], b[8], a[8], centre[8], spread[8];
      _mm256_store_ps(r, _mm512_maskz_cvtpd_ps(preint::kAll, seg.r));
      _mm256_store_ps(g, _mm512_maskz_cvtpd_ps(preint::kAll, seg.g));
      _mm256_store_ps(b, _mm512_maskz_cvtpd_ps(preint::kAll, seg.b));
      _mm256_store_ps(a, _mm512_maskz_cvtpd_ps(preint::kAll, seg.a));
      if constexpr (kShaded) {
        _mm256_store_ps(centre, _mm512_maskz_cvtpd_ps(preint::kAll, seg.centre));
        _mm256_store_ps(spread, _mm512_maskz_cvtpd_ps(preint::kAll, seg.spread));
      }
      // Composite the segments that add anything, in order.
      unsigned lanes = valid & (unsigned(_mm512_cmp_pd_mask(seg.a, _mm512_setzero_pd(), _CMP_GT_OQ)) | seg.opaque);
      for (; lanes; lanes &= lanes - 1) {
        const int lane = __builtin_ctz(lanes);
        Rgba c{r[lane], g[lane], b[lane], a[lane]};
        float middle = 0.5f, around = 0.0f;  // opaque segments are lit at their middle (segment())
        if (seg.opaque & (1u << lane)) {
          c = preint::opaqueSegment(p.preint, frontX[lane], backX[lane]);
        } else if constexpr (kShaded) {
          middle = centre[lane];
          around = spread[lane];
        }
        if constexpr (kShaded) c = shadeSegment(v, p, ray, float(s + lane), 1.0f, middle, around, c);
        acc.addBehind(c);
      }
#else
      if (s + 8 + kFullBatchesOnly < exit) nextAfter = aroundBatch<T, kShifted>(v, p, o, d, s + 10, nextLo, nextHi);
      alignas(32) float back[8], raw[9];
      _mm256_store_ps(back, node);
      _mm256_storeu_ps(raw, before8);
      raw[8] = _mm256_cvtss_f32(_mm256_permutevar8x32_ps(at, _mm256_set1_epi32(7)));
      for (int lane = 0; lane < 8; ++lane) {
        const preint::End backEnd = segmentEnd<T>(p, back[lane]);
        float centre = 0.5f, spread = 0.0f;
        Rgba c = finite<T>(raw[lane]) && finite<T>(raw[lane + 1])
                     ? preint::segment(p.preint, frontEnd, backEnd, p.stepLength, &centre, &spread)
                     : Rgba{};
        frontEnd = backEnd;
        if constexpr (kShaded) {
          if (!(c.a > 0)) continue;
          c = shadeSegment(v, p, ray, float(s + lane), 1.0f, centre, spread, c);
        }
        acc.addBehind(c);
      }
#endif
      advance(s, count, after, lo8, hi8);
      if (acc.a >= p.earlyTermination) return true;
    }
    return false;
  };
#ifdef PVR_HAVE_PREINT_LANES
  if (!kShaded && !p.preint.opaqueNodes) return batches(Rows{});
#endif
  return batches(Cells{});
}

template <typename T, bool kShaded, typename More = NoFollowOn>
inline bool runBatchedPreintegrated(const KernelParams& p, const RaySetup& ray, std::int64_t& start,
                                    std::int64_t exit, Accumulator& acc, std::uint64_t& samples,
                                    More&& more = More{}) {
  if (p.strideShift[0] >= 0)
    return runPreintegratedIndexed<T, kShaded, true>(p, ray, start, exit, acc, samples, std::forward<More>(more));
  return runPreintegratedIndexed<T, kShaded, false>(p, ray, start, exit, acc, samples, std::forward<More>(more));
}

}  // namespace pvr::core::kernel

#endif
