// The starts of castRays' rays in the eight lanes of AVX-512 vectors
// (startInLanes): RayWalk::start's ray-box clips (sampleRange's owned
// box, clipToVisible's visible box, chordEnds' domain) and its exact
// membership tests (inside, inDomain) for eight rays at once, each lane
// with exactly the scalar arithmetic, so that every ray starts where
// RayWalk::start starts it: the same samples, walk and chord ends, and so
// the same images, bit for bit.
//
// Why: one at a time, a ray's start is three clips and about ten
// membership tests in while loops whose trip counts and early exits vary
// from ray to ray, so their branches mispredict. Here the loops become
// windows of candidate samples around the clips' estimates, tested
// together into masks: the membership of a ray's samples is an interval
// (each coordinate fma(k, step, origin) is monotonic in k, and the box is
// convex), so its first member is the lowest member of a window whose
// bottom sample is not one, and its last the highest of a window whose
// top is not. A lane whose windows do not show that (an estimate further
// off than the window, a ray that clips a corner of the brick between
// two samples, a short chord this brick draws) is started by
// RayWalk::start, which decides as it always did (peer scene: none of
// 262144 rays; CT head: 0.4 %). The membership tests round
// fma(k, step, origin) once in both forms (kernel::walkMulAdd), so that a
// sample a rounding from a face is in or out alike.
//
// Peer scene, step 0.5, one thread: the rays' set-up and start (a
// temporary hack that stops each ray after its start) 14.9 -> 11.5 ms a
// frame, the whole frame 137.4 -> 133.1 ms, medians at load 3-4
// (bench/results/plain.txt, section 7).
#pragma once

#include "kernel.h"
#include "tile_start.h"

#ifdef PVR_HAVE_WALK_LANES

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "preint_lanes.h"

namespace pvr::core::kernel {

inline constexpr int kStartLanes = 8;

// Eight rays' starts: which need RayWalk::start, which hit (have samples
// in the brick), which walk, and where (WalkStart's fields by lane).
struct StartsInLanes {
  __mmask8 scalar = 0, hit = 0, walks = 0;
  alignas(64) std::int64_t first[kStartLanes], last[kStartLanes], k[kStartLanes], end[kStartLanes];
  alignas(64) std::int64_t endsFirst[kStartLanes], endsLast[kStartLanes];
  alignas(64) double head[kStartLanes], tail[kStartLanes];

  WalkStart at(int i) const { return {first[i], last[i], k[i], end[i], {endsFirst[i], endsLast[i], head[i], tail[i]}}; }
};

namespace start_lanes {

using preint::kAll;

// A box in index units for the lanes: its bounds along each axis, the
// same in every lane.
struct Box {
  __m512d lo[3], hi[3];
};

// clipToBox() in lanes: narrows [kmin, kmax] along each axis the lane's ray
// moves on, by the same products and comparisons; returns the lanes that
// miss the box along an axis their ray does not move on. std::max(a, b)
// is (a < b ? b : a), which is MAXPD(b, a) exactly (NaN and signed zeros
// included); std::min(a, b) likewise MINPD(b, a).
[[gnu::always_inline]] inline __mmask8 clip(const __m512d* o, const __m512d* s, const __m512d* inv, const Box& box,
                                            __m512d& kmin, __m512d& kmax) {
  __mmask8 miss = 0;
  for (int a = 0; a < 3; ++a) {
    const __mmask8 still = _mm512_cmp_pd_mask(s[a], _mm512_setzero_pd(), _CMP_EQ_OQ);
    const __mmask8 within =
        _mm512_mask_cmp_pd_mask(_mm512_cmp_pd_mask(o[a], box.lo[a], _CMP_GE_OQ), o[a], box.hi[a], _CMP_LE_OQ);
    miss |= still & ~within;
    const __m512d k0 = _mm512_maskz_mul_pd(kAll, _mm512_maskz_sub_pd(kAll, box.lo[a], o[a]), inv[a]);
    const __m512d k1 = _mm512_maskz_mul_pd(kAll, _mm512_maskz_sub_pd(kAll, box.hi[a], o[a]), inv[a]);
    const __mmask8 swap = _mm512_cmp_pd_mask(k0, k1, _CMP_GT_OQ);
    const __m512d nearK = _mm512_mask_blend_pd(swap, k0, k1), farK = _mm512_mask_blend_pd(swap, k1, k0);
    kmin = _mm512_mask_max_pd(kmin, __mmask8(~still), nearK, kmin);
    kmax = _mm512_mask_min_pd(kmax, __mmask8(~still), farK, kmax);
  }
  return miss;
}

// The lanes whose sample k (in steps: a whole sample, or a short chord's
// midpoint) lies in `box`, closed: each coordinate fma(k, step, origin),
// as kernel::walkMulAdd rounds it in inside() and inDomain().
[[gnu::always_inline]] inline __mmask8 members(__m512d k, const __m512d* o, const __m512d* s, const Box& box) {
  __mmask8 in = kAll;
  for (int a = 0; a < 3; ++a) {
    const __m512d u = _mm512_fmadd_pd(k, s[a], o[a]);
    in = _mm512_mask_cmp_pd_mask(in, u, box.lo[a], _CMP_GE_OQ);
    in = _mm512_mask_cmp_pd_mask(in, u, box.hi[a], _CMP_LE_OQ);
  }
  return in;
}

[[gnu::always_inline]] inline __m512d asDouble(__m512i k) { return _mm512_maskz_cvtepi64_pd(kAll, k); }
[[gnu::always_inline]] inline __m512i plus(__m512i k, std::int64_t d) { return _mm512_add_epi64(k, _mm512_set1_epi64(d)); }

// The least member k >= 0 of the lanes' intervals of members, from the
// window of samples c - 1, c, c + 1 around an estimate c >= 0; `found`:
// the lanes whose window shows it (its lowest member >= 0 is not its
// bottom sample, so the sample below is not a member, or below 0). The
// clips' estimates are within far less than a sample of the exact ends
// (rounding), so three samples show them but where a ray has none.
[[gnu::always_inline]] inline __m512i firstMember(__m512i c, const __m512d* o, const __m512d* s, const Box& box,
                                                  __mmask8& found) {
  __mmask8 in[3];
  for (int j = 0; j < 3; ++j) in[j] = members(asDouble(plus(c, j - 1)), o, s, box);
  in[0] &= _mm512_cmpge_epi64_mask(c, _mm512_set1_epi64(1));  // samples below 0 are no members
  found = __mmask8((in[1] | in[2]) & ~in[0]);
  return _mm512_mask_mov_epi64(plus(c, 1), in[1], c);
}

// The greatest member of the lanes' intervals of members, from the window
// of samples f - 1, f, f + 1 around an estimate f; `found`: the lanes whose
// window shows it (its highest member is not its top sample).
[[gnu::always_inline]] inline __m512i lastMember(__m512i f, const __m512d* o, const __m512d* s, const Box& box,
                                                 __mmask8& found) {
  __mmask8 in[3];
  for (int j = 0; j < 3; ++j) in[j] = members(asDouble(plus(f, j - 1)), o, s, box);
  found = __mmask8((in[0] | in[1]) & ~in[2]);
  return _mm512_mask_mov_epi64(plus(f, -1), in[1], f);
}

// std::int64_t(std::ceil(x)) and std::int64_t(std::floor(x)) for x well
// within the int64 range.
[[gnu::always_inline]] inline __m512i ceilToInt(__m512d x) {
  return _mm512_maskz_cvt_roundpd_epi64(kAll, x, _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC);
}
[[gnu::always_inline]] inline __m512i floorToInt(__m512d x) {
  return _mm512_maskz_cvt_roundpd_epi64(kAll, x, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
}

// std::clamp(x, 0.0, 1.0): (x < 0 ? 0 : 1 < x ? 1 : x).
[[gnu::always_inline]] inline __m512d clampUnit(__m512d x) {
  const __m512d one = _mm512_set1_pd(1.0);
  const __m512d upTo1 = _mm512_mask_blend_pd(_mm512_cmp_pd_mask(one, x, _CMP_LT_OQ), x, one);
  return _mm512_mask_blend_pd(_mm512_cmp_pd_mask(x, _mm512_setzero_pd(), _CMP_LT_OQ), upTo1, _mm512_setzero_pd());
}

}  // namespace start_lanes

// What the starts of one castRays call share: the brick's boxes and the
// tile's span, in every lane.
class StartLanes {
 public:
  StartLanes(const KernelParams& p, const TileSpan& span) {
    bool ownsDomain = true;
    for (int a = 0; a < 3; ++a) {
      // inside()'s u < ownHi where the far face is open is u <= the
      // greatest double below ownHi: one closed test for both.
      const double ownHi = p.hiClosed[a] ? p.ownHi[a] : std::nextafter(p.ownHi[a], -INFINITY);
      own_.lo[a] = _mm512_set1_pd(p.ownLo[a]);
      own_.hi[a] = _mm512_set1_pd(p.ownHi[a]);
      owned_.lo[a] = own_.lo[a];
      owned_.hi[a] = _mm512_set1_pd(ownHi);
      domain_.lo[a] = _mm512_setzero_pd();
      domain_.hi[a] = _mm512_set1_pd(double(p.domainMax[a]));
      visible_.lo[a] = _mm512_set1_pd(p.visibleLo[a]);
      visible_.hi[a] = _mm512_set1_pd(p.visibleHi[a]);
      nothingVisible_ |= !(p.visibleLo[a] <= p.visibleHi[a]);
      ownsDomain &= p.ownLo[a] == 0.0 && p.ownHi[a] == double(p.domainMax[a]) && p.hiClosed[a];
    }
    ownsDomain_ = ownsDomain;
    from_ = _mm512_set1_epi64(span.from);
    to_ = _mm512_set1_epi64(span.to);
  }

  // The starts of rays[0, n), 0 < n <= kStartLanes, into `s`.
  void start(const RaySetup* rays, int n, StartsInLanes& s) const {
    using namespace start_lanes;
    // The rays' origins, steps and inverse steps, lane i from rays[i]
    // (lanes past n from rays[0]; their results are never read): the
    // first eight of those nine doubles of each ray by one load and a
    // transpose, the last by a gather (nine gathers were half of this
    // function's time; ~20 % less of it so: bench/results/plain.txt,
    // section 7).
    static_assert(offsetof(RaySetup, step) == 3 * sizeof(double) && offsetof(RaySetup, invStep) == 6 * sizeof(double),
                  "origin, step and invStep lie side by side");
    __m512d rows[kStartLanes];
    for (int i = 0; i < kStartLanes; ++i) rows[i] = _mm512_loadu_pd(rays[i < n ? i : 0].origin);
    preint::transpose8x8(rows);
    alignas(64) std::int64_t offsets[kStartLanes];
    for (int i = 0; i < kStartLanes; ++i) offsets[i] = i < n ? std::int64_t(i * sizeof(RaySetup)) : 0;
    const __m512d o[3] = {rows[0], rows[1], rows[2]}, d[3] = {rows[3], rows[4], rows[5]};
    const __m512d inv[3] = {rows[6], rows[7],
                            _mm512_mask_i64gather_pd(_mm512_setzero_pd(), kAll, _mm512_load_si512(offsets),
                                                     &rays[0].invStep[2], 1)};
    const __m512d zero = _mm512_setzero_pd();
    // Estimates beyond this many samples are left to RayWalk::start (their
    // conversions to integers would be nonsense).
    const __m512d far = _mm512_set1_pd(0x1p50);

    // sampleRange's clip of the owned box.
    __m512d kmin = zero, kmax = _mm512_set1_pd(1e18);
    const __mmask8 outside = clip(o, d, inv, own_, kmin, kmax);
    const __mmask8 missed = outside | _mm512_cmp_pd_mask(kmin, _mm512_add_pd(kmax, _mm512_set1_pd(2.0)), _CMP_GT_OQ);

    // The domain's clip (domainChord): the owned box's when the brick owns
    // the whole domain (the same bounds, so the same products).
    __m512d kIn = kmin, kOut = kmax;
    __mmask8 chord = __mmask8(~outside) & _mm512_cmp_pd_mask(kmin, kmax, _CMP_LE_OQ);
    if (!ownsDomain_) {
      kIn = zero;
      kOut = _mm512_set1_pd(1e18);
      chord = __mmask8(~clip(o, d, inv, domain_, kIn, kOut)) & _mm512_cmp_pd_mask(kIn, kOut, _CMP_LE_OQ);
    }
    // A ray without an owned sample hits nothing here unless its chord
    // through the domain is a short one (shortChord: no sample around its
    // entry in the domain) whose midpoint this brick owns; RayWalk::start
    // draws those.
    __mmask8 none = missed & ~chord;
    if (const __mmask8 crossing = missed & chord & _mm512_cmp_pd_mask(kIn, far, _CMP_LT_OQ)) {
      const __m512i c = ceilToInt(kIn);
      // Samples max(0, c - 1) .. c + 1, c the entry's estimate.
      __mmask8 sampled = members(asDouble(c), o, d, domain_) | members(asDouble(plus(c, 1)), o, d, domain_);
      sampled |= members(asDouble(plus(c, -1)), o, d, domain_) & _mm512_cmpge_epi64_mask(c, _mm512_set1_epi64(1));
      const __m512d mid = _mm512_maskz_mul_pd(kAll, _mm512_set1_pd(0.5), _mm512_maskz_add_pd(kAll, kIn, kOut));
      none |= crossing & (sampled | __mmask8(~members(mid, o, d, owned_)));
    }
    // Rays that miss the brick and the domain (the background) cost no more.
    if (none == kAll) {
      s.hit = s.scalar = s.walks = 0;
      return;
    }
    // sampleRange's samples: the owned box's first member >= 0 and its
    // last, from windows around the clip's estimates. (RayWalk::start
    // looks up from max(0, ceil(kmin) - 1) and down from floor(kmax) + 1,
    // and finds the interval's ends when it meets that range: where the
    // windows show the ends, they lie in that range, and it is met when
    // first <= last.)
    __mmask8 usual = _mm512_cmp_pd_mask(kmin, far, _CMP_LT_OQ) & _mm512_cmp_pd_mask(kmax, far, _CMP_LT_OQ) &
                     _mm512_cmp_pd_mask(kmax, -far, _CMP_GT_OQ);
    __mmask8 foundFirst, foundLast;
    const __m512i first = firstMember(ceilToInt(kmin), o, d, owned_, foundFirst);
    const __m512i last = lastMember(floorToInt(kmax), o, d, owned_, foundLast);
    usual &= foundFirst & foundLast & _mm512_cmple_epi64_mask(first, last);
    s.hit = __mmask8(~missed & usual);
    s.scalar = __mmask8(~none & ~s.hit);

    // clipToVisible, then clipToWalk's span.
    const __m512d firstD = asDouble(first);
    __m512d vmin = firstD, vmax = asDouble(last);
    __mmask8 walks = s.hit;
    if (nothingVisible_) walks = 0;
    walks &= __mmask8(~clip(o, d, inv, visible_, vmin, vmax)) & _mm512_cmp_pd_mask(vmin, vmax, _CMP_LE_OQ);
    __m512i k = _mm512_maskz_max_epi64(kAll, _mm512_maskz_max_epi64(kAll, first, floorToInt(vmin)), from_);
    __m512i end = _mm512_maskz_min_epi64(kAll, _mm512_maskz_min_epi64(kAll, last, ceilToInt(vmax)), to_);
    walks &= _mm512_cmple_epi64_mask(k, end);

    // chordEnds: its ends are the domain's first member >= 0 and its last
    // (whatever its estimates; see ChordEnds), which are the owned box's
    // when the brick owns the domain.
    kIn = _mm512_mask_blend_pd(chord, firstD, kIn);
    kOut = _mm512_mask_blend_pd(chord, firstD, kOut);
    __m512i endsFirst = first, endsLast = last;
    if (!ownsDomain_) {
      __mmask8 foundIn, foundOut;
      endsFirst = firstMember(ceilToInt(kIn), o, d, domain_, foundIn);
      endsLast = lastMember(floorToInt(kOut), o, d, domain_, foundOut);
      const __mmask8 resolved = foundIn & foundOut & _mm512_cmp_pd_mask(kOut, far, _CMP_LT_OQ);
      s.scalar |= walks & ~resolved;
      walks &= resolved;
      s.hit &= ~s.scalar;
    }
    s.walks = walks;
    const __m512d head = clampUnit(_mm512_maskz_sub_pd(kAll, asDouble(endsFirst), kIn));
    const __m512d tail = clampUnit(_mm512_maskz_sub_pd(kAll, kOut, asDouble(endsLast)));
    _mm512_store_si512(s.first, first);
    _mm512_store_si512(s.last, last);
    _mm512_store_si512(s.k, k);
    _mm512_store_si512(s.end, end);
    _mm512_store_si512(s.endsFirst, endsFirst);
    _mm512_store_si512(s.endsLast, endsLast);
    _mm512_store_pd(s.head, head);
    _mm512_store_pd(s.tail, tail);
  }

 private:
  start_lanes::Box own_;      // the owned box as clipToBox takes it
  start_lanes::Box owned_;    // ... and as inside() tests it, closed
  start_lanes::Box domain_;   // [0, dims - 1]
  start_lanes::Box visible_;  // KernelParams::visibleLo, visibleHi
  __m512i from_, to_;         // the tile's span
  bool ownsDomain_ = false;   // the owned box is the domain, closed at every far face
  bool nothingVisible_ = false;
};

// castRays' walks walk[0, n) started for rays[0, n), n <= kRaysAtOnce,
// eight at a time in lanes (StartLanes), each where RayWalk::start
// starts it (the unusual rays by RayWalk::start itself): going[i] when
// walk i goes on, out[i] the results of those that do not. Returns how
// many go on.
template <typename Walk>
int startInLanes(const KernelParams& p, const RaySetup* rays, int n, int mcShift, const TileSpan& span, Walk* walk,
                 bool* going, RayResult* out) {
  const StartLanes lanes(p, span);
  StartsInLanes s;
  int left = 0;
  for (int g = 0; g < n; g += kStartLanes) {
    lanes.start(rays + g, std::min(kStartLanes, n - g), s);
    for (int i = 0; i < kStartLanes && g + i < n; ++i) {
      const int r = g + i;
      out[r] = RayResult{};
      if ((s.scalar >> i) & 1) {
        going[r] = walk[r].start(p, rays[r], mcShift, span, out[r]);
      } else {
        out[r].hit = (s.hit >> i) & 1;
        going[r] = (s.walks >> i) & 1;
        if (going[r]) walk[r].begin(p, rays[r], mcShift, s.at(i));
      }
      left += going[r];
    }
  }
  return left;
}

}  // namespace pvr::core::kernel

#endif
