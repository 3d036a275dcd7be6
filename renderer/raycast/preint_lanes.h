// Eight pre-integrated segments at once: preintegration.h's endAt() and
// segment() across the eight lanes of a batch, in AVX-512 double.
//
// Double, because a segment's integral is a difference of two cumulative
// sums (preintegration.h); eight doubles fill one 512-bit vector, so this
// costs the instructions that eight floats in AVX2 would. The table is read
// as rows, not gathered: each lane's cell is two 64-byte loads, and two
// 8x8 transposes turn the eight cells into one vector per field (this
// machine's hardware gathers cost ~19 cycles each; a transpose is 24
// shuffles for 64 values). Opaque segments, rare, stay per lane
// (preint::opaqueSegment).
#pragma once

#if defined(__AVX512F__) && defined(__AVX512DQ__)
#define PVR_HAVE_PREINT_LANES 1

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include "../preintegration.h"

namespace pvr::core::preint {

// Every lane. The masked forms of the intrinsics, with this mask, compile to
// the unmasked instructions; the unmasked forms start from GCC 12's
// "undefined" vectors, which -Wmaybe-uninitialized reports at every use.
inline constexpr __mmask8 kAll = 0xff;

// The integrals at eight segment ends (End, one field per vector).
struct Ends8 {
  __m512d x, tau, T, M, K[3], O, k[3], opaque;
};

// Row j of r becomes column j: r[f][j] = old r[j][f].
[[gnu::always_inline]] inline void transpose8x8(__m512d r[8]) {
  __m512d t[8], u[8];
  for (int j = 0; j < 8; j += 2) {
    t[j] = _mm512_maskz_unpacklo_pd(kAll, r[j], r[j + 1]);      // r[j][0] r[j+1][0] r[j][2] r[j+1][2] ...
    t[j + 1] = _mm512_maskz_unpackhi_pd(kAll, r[j], r[j + 1]);  // r[j][1] r[j+1][1] r[j][3] r[j+1][3] ...
  }
  // 128-bit pairs of rows j, j+1 beside those of rows j+2, j+3.
  const __m512i even = _mm512_setr_epi64(0, 1, 8, 9, 4, 5, 12, 13);
  const __m512i odd = _mm512_setr_epi64(2, 3, 10, 11, 6, 7, 14, 15);
  for (int h = 0; h < 8; h += 4) {
    u[h + 0] = _mm512_permutex2var_pd(t[h + 0], even, t[h + 2]);  // fields 0 and 4 of rows h..h+3
    u[h + 1] = _mm512_permutex2var_pd(t[h + 1], even, t[h + 3]);  // fields 1 and 5
    u[h + 2] = _mm512_permutex2var_pd(t[h + 0], odd, t[h + 2]);   // fields 2 and 6
    u[h + 3] = _mm512_permutex2var_pd(t[h + 1], odd, t[h + 3]);   // fields 3 and 7
  }
  // Rows 0..3 beside rows 4..7.
  for (int f = 0; f < 4; ++f) {
    r[f] = _mm512_maskz_shuffle_f64x2(kAll, u[f], u[4 + f], 0x44);
    r[f + 4] = _mm512_maskz_shuffle_f64x2(kAll, u[f], u[4 + f], 0xEE);
  }
}

// Table coordinates of eight scalars: x, clamped into the table (xc), the
// cell, the fraction across it and the part beyond the table.
struct Coordinates8 {
  __m512d x, xc, w, beyond;
  __m256i cell;
};

[[gnu::always_inline]] inline Coordinates8 coordinates(const PreintegralTables& t, __m256 scalar) {
  Coordinates8 c;
  c.x = _mm512_add_pd(_mm512_mul_pd(_mm512_maskz_cvtps_pd(kAll, scalar), _mm512_set1_pd(double(t.scale))),
                      _mm512_set1_pd(double(t.offset)));
  c.xc = _mm512_maskz_min_pd(kAll, _mm512_maskz_max_pd(kAll, c.x, _mm512_setzero_pd()),
                              _mm512_set1_pd(double(t.entries - 1)));
  c.cell = _mm256_min_epi32(_mm512_maskz_cvttpd_epi32(kAll, c.xc), _mm256_set1_epi32(t.entries - 2));
  c.w = _mm512_sub_pd(c.xc, _mm512_maskz_cvtepi32_pd(kAll, c.cell));
  c.beyond = _mm512_sub_pd(c.x, c.xc);
  return c;
}

// endAt() of eight finite scalars.
[[gnu::always_inline]] inline Ends8 endsAt(const PreintegralTables& t, __m256 scalar) {
  Ends8 e;
  const Coordinates8 at = coordinates(t, scalar);
  e.x = at.x;
  const __m512d xc = at.xc, di = _mm512_maskz_cvtepi32_pd(kAll, at.cell);
  const __m512d w = at.w, beyond = at.beyond;
  alignas(32) std::int32_t cell[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(cell), at.cell);
  __m512d row0[8], row1[8];
  for (int j = 0; j < 8; ++j) {
    const double* c = &t.cells[cell[j]].tau;
    row0[j] = _mm512_load_pd(c);
    row1[j] = _mm512_load_pd(c + 8);
  }
  transpose8x8(row0);  // tau dtau T M K0 K1 K2 O
  transpose8x8(row1);  // k0 k1 k2 dk0 dk1 dk2 opaque dopaque
  const __m512d half = _mm512_set1_pd(0.5);
  // point: f_a + w df; partial: w (f_a + w/2 df), as endAt().
  auto point = [&](__m512d fa, __m512d df) __attribute__((always_inline)) { return _mm512_fmadd_pd(w, df, fa); };
  auto partial = [&](__m512d fa, __m512d df) __attribute__((always_inline)) {
    return _mm512_mul_pd(w, _mm512_fmadd_pd(_mm512_mul_pd(half, w), df, fa));
  };
  e.tau = point(row0[0], row0[1]);
  const __m512d partialT = partial(row0[0], row0[1]);
  e.T = _mm512_fmadd_pd(beyond, e.tau, _mm512_add_pd(row0[2], partialT));
  // M: i * partial + w^2 (tau_a / 2 + w dtau / 3) + tau beyond (x + xc) / 2.
  const __m512d curve = _mm512_fmadd_pd(_mm512_mul_pd(w, row0[1]), _mm512_set1_pd(1.0 / 3),
                                        _mm512_mul_pd(half, row0[0]));
  const __m512d outside = _mm512_mul_pd(_mm512_mul_pd(half, e.tau), _mm512_mul_pd(beyond, _mm512_add_pd(e.x, xc)));
  e.M = _mm512_add_pd(_mm512_add_pd(row0[3], _mm512_mul_pd(di, partialT)),
                      _mm512_fmadd_pd(_mm512_mul_pd(w, w), curve, outside));
  for (int c = 0; c < 3; ++c) {
    e.k[c] = point(row1[c], row1[3 + c]);
    e.K[c] = _mm512_fmadd_pd(beyond, e.k[c], _mm512_add_pd(row0[4 + c], partial(row1[c], row1[3 + c])));
  }
  e.opaque = point(row1[6], row1[7]);
  e.O = _mm512_fmadd_pd(beyond, e.opaque, _mm512_add_pd(row0[7], partial(row1[6], row1[7])));
  return e;
}

// True when the eight scalars and `front` all lie in empty cells
// (visibleBelow), with a cell of margin for the float rounding of their
// table coordinates: no segment between them integrates anything.
[[gnu::always_inline]] inline bool allEmpty(const PreintegralTables& t, __m256 scalar, float front) {
  const __m256 scale = _mm256_set1_ps(t.scale), offset = _mm256_set1_ps(t.offset), f = _mm256_set1_ps(front);
  // Least and greatest table coordinate (scale >= 0), in every lane.
  __m256 lo = _mm256_fmadd_ps(_mm256_min_ps(scalar, f), scale, offset);
  __m256 hi = _mm256_fmadd_ps(_mm256_max_ps(scalar, f), scale, offset);
  lo = _mm256_min_ps(lo, _mm256_permute2f128_ps(lo, lo, 1));
  hi = _mm256_max_ps(hi, _mm256_permute2f128_ps(hi, hi, 1));
  lo = _mm256_min_ps(lo, _mm256_shuffle_ps(lo, lo, 0x4e));
  hi = _mm256_max_ps(hi, _mm256_shuffle_ps(hi, hi, 0x4e));
  lo = _mm256_min_ps(lo, _mm256_shuffle_ps(lo, lo, 0xb1));
  hi = _mm256_max_ps(hi, _mm256_shuffle_ps(hi, hi, 0xb1));
  const float last = float(t.entries - 1);
  auto cell = [&](float x) __attribute__((always_inline)) {
    return std::min(int(std::clamp(x, 0.0f, last)), t.entries - 2);
  };
  const int first = std::max(cell(_mm256_cvtss_f32(lo)) - 1, 0);
  const int final = std::min(cell(_mm256_cvtss_f32(hi)) + 1, t.entries - 2);
  return t.visibleBelow[final + 1] == t.visibleBelow[first];
}

// True when the eight scalars and `front` all lie in the transfer
// function's empty low end, or all in its empty high end
// (PreintegralTables::clearBelow, clearAbove): where the table has no empty
// cells between visible ones, exactly allEmpty(), lane by lane and without
// its reductions across the lanes and scalar clamps, whose chain of
// dependent instructions before the batch's branch was a fifth of an
// unshaded pre-integrated frame.
[[gnu::always_inline]] inline bool allClear(const PreintegralTables& t, __m256 scalar, float front) {
  const __m256 scale = _mm256_set1_ps(t.scale), offset = _mm256_set1_ps(t.offset);
  const __m256 x = _mm256_fmadd_ps(scalar, scale, offset);
  const __m256 f = _mm256_fmadd_ps(_mm256_set1_ps(front), scale, offset);
  const __m256 below = _mm256_set1_ps(t.clearBelow), above = _mm256_set1_ps(t.clearAbove);
  const int low = _mm256_movemask_ps(_mm256_and_ps(_mm256_cmp_ps(x, below, _CMP_LT_OQ), _mm256_cmp_ps(f, below, _CMP_LT_OQ)));
  const int high = _mm256_movemask_ps(_mm256_and_ps(_mm256_cmp_ps(x, above, _CMP_GE_OQ), _mm256_cmp_ps(f, above, _CMP_GE_OQ)));
  return low == 0xFF || high == 0xFF;
}

// The eight ends of a batch kept in memory, field by field, for the next
// batch's fronts (lane 7: the next segment's front end). Carried in
// registers, the 14 vectors of a batch's ends outlived the batch and the
// compiler spilled them and others around the segment arithmetic; stored
// once here, the next batch reads lane 7 of each with a broadcast load.
struct StoredEnds {
  enum Field { kX, kTau, kT, kM, kK0, kK1, kK2, kO, kk0, kk1, kk2, kOpaque, kFields };
  alignas(64) double lanes[kFields][8];
};

[[gnu::always_inline]] inline void store(const Ends8& e, StoredEnds& s) {
  _mm512_store_pd(s.lanes[StoredEnds::kX], e.x);
  _mm512_store_pd(s.lanes[StoredEnds::kTau], e.tau);
  _mm512_store_pd(s.lanes[StoredEnds::kT], e.T);
  _mm512_store_pd(s.lanes[StoredEnds::kM], e.M);
  _mm512_store_pd(s.lanes[StoredEnds::kO], e.O);
  _mm512_store_pd(s.lanes[StoredEnds::kOpaque], e.opaque);
  for (int c = 0; c < 3; ++c) {
    _mm512_store_pd(s.lanes[StoredEnds::kK0 + c], e.K[c]);
    _mm512_store_pd(s.lanes[StoredEnds::kk0 + c], e.k[c]);
  }
}

// One End as lane 7 of `s` (the other lanes are not read).
inline void store(const End& end, StoredEnds& s) {
  s.lanes[StoredEnds::kX][7] = end.x;
  s.lanes[StoredEnds::kTau][7] = end.tau;
  s.lanes[StoredEnds::kT][7] = end.T;
  s.lanes[StoredEnds::kM][7] = end.M;
  s.lanes[StoredEnds::kO][7] = end.O;
  s.lanes[StoredEnds::kOpaque][7] = end.opaque;
  for (int c = 0; c < 3; ++c) {
    s.lanes[StoredEnds::kK0 + c][7] = end.K[c];
    s.lanes[StoredEnds::kk0 + c][7] = end.k[c];
  }
}

// The eight ends before these: lane 0 from lane 7 of `before`, lane j from
// lane j - 1 of `e` (the back end of one segment is the front of the next).
[[gnu::always_inline]] inline Ends8 fronts(const StoredEnds& before, const Ends8& e) {
  auto shift = [&](int field, __m512d a) __attribute__((always_inline)) {
    const __m512d b = _mm512_set1_pd(before.lanes[field][7]);
    return _mm512_castsi512_pd(_mm512_maskz_alignr_epi64(kAll, _mm512_castpd_si512(a), _mm512_castpd_si512(b), 7));
  };
  Ends8 f;
  f.x = shift(StoredEnds::kX, e.x);
  f.tau = shift(StoredEnds::kTau, e.tau);
  f.T = shift(StoredEnds::kT, e.T);
  f.M = shift(StoredEnds::kM, e.M);
  f.O = shift(StoredEnds::kO, e.O);
  f.opaque = shift(StoredEnds::kOpaque, e.opaque);
  for (int c = 0; c < 3; ++c) {
    f.K[c] = shift(StoredEnds::kK0 + c, e.K[c]);
    f.k[c] = shift(StoredEnds::kk0 + c, e.k[c]);
  }
  return f;
}

// 1 / x: the 14-bit estimate and kNewton Newton steps, each doubling its
// bits (a division's divider takes 16 cycles a vector): one step leaves a
// relative error below 2^-28 (4e-9), two steps double precision.
template <int kNewton>
[[gnu::always_inline]] inline __m512d reciprocal(__m512d x) {
  const __m512d one = _mm512_set1_pd(1.0);
  __m512d r = _mm512_maskz_rcp14_pd(kAll, x);
  for (int step = 0; step < kNewton; ++step) r = _mm512_fmadd_pd(r, _mm512_fnmadd_pd(x, r, one), r);
  return r;
}

// expm1(x) for x <= 0: x = n ln2 + r, |r| <= ln2 / 2, a degree-8 Taylor
// polynomial for expm1(r), then 2^n (expm1(r) + 1) - 1, which cannot
// cancel for n != 0. The polynomial's remainder is below
// |r|^9 / 9! e^|r| < 3e-10 (relative to expm1(r), below 6e-10), so an
// opacity 1 - e^x errs by less than 3e-10, which its conversion to float
// (half an ulp: 3e-8 at 1, 3e-10 relative below) rounds away or nearly:
// the image needs 1e-7 (degree 12, for 1e-16, cost an eighth more of the
// segment arithmetic for digits no float output keeps). The remainder
// is |r|^8 / 9! relative, so where segments() cancels digits of the
// opacity (the spread's 1/D^2 - (1 - a)/a^2, 1e5 times near D = 1e-2,
// 100 times at D = 0.35) it is below 1e-20 (D = 1e-2) or the cancellation
// leaves 1e-7 of the spread (D = 0.35), its float rounding. Estrin's scheme,
// not Horner's: four dependent steps instead of eight, on the batch's
// chain of dependent instructions.
[[gnu::always_inline]] inline __m512d expm1NonPositive(__m512d x) {
  x = _mm512_maskz_max_pd(kAll, x, _mm512_set1_pd(-700.0));
  const __m512d n = _mm512_maskz_roundscale_pd(kAll, _mm512_mul_pd(x, _mm512_set1_pd(1.4426950408889634)),
                                         _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
  __m512d r = _mm512_fnmadd_pd(n, _mm512_set1_pd(6.93147180369123816490e-01), x);
  r = _mm512_fnmadd_pd(n, _mm512_set1_pd(1.90821492927058770002e-10), r);
  // expm1(r) / r = sum of r^(m - 1) / m!, m = 1..8: pairs of terms, joined by r^2 and r^4.
  auto term = [](double inverseFactorial) __attribute__((always_inline)) { return _mm512_set1_pd(inverseFactorial); };
  const __m512d r2 = _mm512_mul_pd(r, r), r4 = _mm512_mul_pd(r2, r2);
  const __m512d p1 = _mm512_fmadd_pd(term(1.0 / 2), r, term(1.0)), p3 = _mm512_fmadd_pd(term(1.0 / 24), r, term(1.0 / 6));
  const __m512d p5 = _mm512_fmadd_pd(term(1.0 / 720), r, term(1.0 / 120));
  const __m512d p7 = _mm512_fmadd_pd(term(1.0 / 40320), r, term(1.0 / 5040));
  const __m512d low = _mm512_fmadd_pd(p3, r2, p1), high = _mm512_fmadd_pd(p7, r2, p5);
  const __m512d p = _mm512_mul_pd(_mm512_fmadd_pd(high, r4, low), r);  // expm1(r)
  const __m512d scaled = _mm512_sub_pd(_mm512_maskz_scalef_pd(kAll, _mm512_add_pd(p, _mm512_set1_pd(1.0)), n),
                                       _mm512_set1_pd(1.0));
  return _mm512_mask_blend_pd(_mm512_cmp_pd_mask(n, _mm512_setzero_pd(), _CMP_EQ_OQ), scaled, p);
}

// Eight segments from `f` to `b`, each `length` world units: segment()'s
// premultiplied colour and opacity and, with kCentre, where to light it
// (centre and spread).
// Lanes that segment() would make opaque are flagged in `opaque` and left
// empty here (their colour: opaqueSegment()); so are lanes with no
// extinction.
struct Segments8 {
  __m512d r, g, b, a;
  __m512d centre, spread;
  __mmask8 opaque;
};

// What segments() needs of eight segments' two ends: their differences
// (the integrals across each segment) and sums (for the ends' mean).
struct Spans8 {
  __m512d fx, dx;           // the front's table coordinate; back minus front
  __m512d dT, dK[3];        // back minus front
  __m512d sumTau, sumK[3];  // front plus back (point values)
  __m512d dM, frontTau, backTau;  // with kCentre only
  __mmask8 opaque = 0;      // lanes that reach an opaque scalar
};

template <bool kCentre>
[[gnu::always_inline]] inline Segments8 integrate(const Spans8& e, double length);

template <bool kCentre>
[[gnu::always_inline]] inline Segments8 segments(const Ends8& f, const Ends8& b, double length) {
  const __m512d zero = _mm512_setzero_pd();
  Spans8 e;
  e.fx = f.x;
  e.dx = _mm512_sub_pd(b.x, f.x);
  const __mmask8 wide = _mm512_cmp_pd_mask(_mm512_abs_pd(e.dx), _mm512_set1_pd(kMinSpan), _CMP_GT_OQ);
  e.opaque = (wide & _mm512_cmp_pd_mask(b.O, f.O, _CMP_NEQ_UQ)) | _mm512_cmp_pd_mask(f.opaque, zero, _CMP_GT_OQ) |
             _mm512_cmp_pd_mask(b.opaque, zero, _CMP_GT_OQ);
  e.dT = _mm512_sub_pd(b.T, f.T);
  e.sumTau = _mm512_add_pd(f.tau, b.tau);
  for (int c = 0; c < 3; ++c) {
    e.dK[c] = _mm512_sub_pd(b.K[c], f.K[c]);
    e.sumK[c] = _mm512_add_pd(f.k[c], b.k[c]);
  }
  if constexpr (kCentre) {
    e.dM = _mm512_sub_pd(b.M, f.M);
    e.frontTau = f.tau;
    e.backTau = b.tau;
  }
  return integrate<kCentre>(e, length);
}

template <bool kCentre>
[[gnu::always_inline]] inline Segments8 integrate(const Spans8& e, double length) {
  Segments8 s;
  const __m512d zero = _mm512_setzero_pd(), half = _mm512_set1_pd(0.5);
  const __m512d dx = e.dx;
  const __mmask8 wide = _mm512_cmp_pd_mask(_mm512_abs_pd(dx), _mm512_set1_pd(kMinSpan), _CMP_GT_OQ);
  s.opaque = e.opaque;
  // Mean extinction and colour: difference quotients where the ends are
  // apart, the ends' mean where they are not.
  // 1/dx and 1/tau scale their products by 1 + 4e-9 at most (one Newton
  // step): a colour or opacity 4e-9 off, rounded away by its conversion
  // to float. The centroid's reciprocals keep two steps: its quotient is a
  // table coordinate (up to 4095) from which the front's is subtracted.
  const __m512d inv = reciprocal<1>(dx);  // used where wide only
  const __m512d dT = e.dT;
  const __m512d tau = _mm512_mask_blend_pd(wide, _mm512_mul_pd(half, e.sumTau), _mm512_mul_pd(dT, inv));
  __m512d k[3];
  for (int c = 0; c < 3; ++c)
    k[c] = _mm512_mask_blend_pd(wide, _mm512_mul_pd(half, e.sumK[c]), _mm512_mul_pd(e.dK[c], inv));
  const __mmask8 visible = _mm512_cmp_pd_mask(tau, zero, _CMP_GT_OQ) & ~s.opaque;
  const __m512d depth = _mm512_mul_pd(tau, _mm512_set1_pd(length));
  const __m512d alpha = _mm512_maskz_sub_pd(visible, zero, expm1NonPositive(_mm512_sub_pd(zero, depth)));
  // Mean colour k / tau, times alpha.
  const __m512d weight = _mm512_maskz_mul_pd(visible, alpha, reciprocal<1>(tau));
  s.r = _mm512_mul_pd(k[0], weight);
  s.g = _mm512_mul_pd(k[1], weight);
  s.b = _mm512_mul_pd(k[2], weight);
  s.a = alpha;
  if constexpr (kCentre) {
    // The extinction's centroid, then moved frontwards by self-attenuation
    // (segment()): 1/D - 1/(e^D - 1) - 1/2, with 1/(e^D - 1) = (1 - alpha) / alpha.
    const __m512d sum = e.sumTau;
    const __m512d num = _mm512_mask_blend_pd(wide, _mm512_fmadd_pd(_mm512_set1_pd(2.0), e.backTau, e.frontTau), e.dM);
    const __m512d den = _mm512_mask_blend_pd(wide, _mm512_mul_pd(_mm512_set1_pd(3.0), sum), dT);
    const __m512d quotient = _mm512_mul_pd(num, reciprocal<2>(den));
    __m512d at = _mm512_mask_blend_pd(wide, quotient, _mm512_mul_pd(_mm512_sub_pd(quotient, e.fx), inv));
    at = _mm512_mask_blend_pd(wide | _mm512_cmp_pd_mask(sum, zero, _CMP_GT_OQ), half, at);
    const __m512d one = _mm512_set1_pd(1.0);
    const __m512d inverseDepth = reciprocal<2>(depth), inverseAlpha = reciprocal<2>(alpha);
    const __m512d transmitted = _mm512_mul_pd(_mm512_sub_pd(one, alpha), inverseAlpha);  // 1 / (e^D - 1)
    const __m512d thick = _mm512_sub_pd(_mm512_sub_pd(inverseDepth, transmitted), half);
    const __mmask8 thin = _mm512_cmp_pd_mask(depth, _mm512_set1_pd(1e-3), _CMP_LT_OQ);
    at = _mm512_add_pd(at, _mm512_mask_blend_pd(thin, thick, _mm512_mul_pd(depth, _mm512_set1_pd(-1.0 / 12))));
    s.centre = _mm512_maskz_min_pd(kAll, _mm512_maskz_max_pd(kAll, at, zero), one);
    // emissionVariance(), and its square root.
    const __m512d variance = _mm512_mask_blend_pd(
        _mm512_cmp_pd_mask(depth, _mm512_set1_pd(1e-2), _CMP_LT_OQ),
        _mm512_fmsub_pd(inverseDepth, inverseDepth, _mm512_mul_pd(transmitted, inverseAlpha)),
        _mm512_fnmadd_pd(_mm512_mul_pd(depth, depth), _mm512_set1_pd(1.0 / 240), _mm512_set1_pd(1.0 / 12)));
    s.spread = _mm512_maskz_sqrt_pd(kAll, _mm512_maskz_max_pd(kAll, variance, zero));
  }
  return s;
}

// The rows look-up (PreintegralRows), for tables without opaque nodes and
// segments not lit: each end is one row, T K0 K1 K2 | tau k0 k1 k2 at its
// scalar, computed with endsAt()'s operations (so equal to it to the ulp
// that the compiler's fusing of a multiply and an add may change);
// a segment's differences and sums are one fused multiply-add of two
// consecutive rows, and one 8x8 transpose makes them vectors across the
// eight segments. Precision: the rows hold the cells' doubles (curve =
// slope / 2 exactly) and the differences are the same double
// subtractions, so the precision is the cells': an end's cumulative T is
// rounded to half an ulp of at most T's top (below 4095 cells times the
// densest extinction tau_max), and T(b) - T(f) errs by three such,
// 3 * 1.1e-16 * 4095 tau_max = 1.4e-12 tau_max; over a wide segment
// (|dx| > kMinSpan = 1e-2 cells) its mean extinction errs by 1.4e-10
// tau_max. Relative to the segment's own extinction that is below the
// 1e-7 the image needs wherever the mean is above 1.4e-3 tau_max, and
// fainter segments err by less than 1.4e-10 of the densest segment's
// depth, absolutely: far below the float the opacity is returned in.
// Narrow segments take the ends' point values (no difference of sums),
// exact to an ulp. Float rows would not be cheaper: converting 16 float
// fields to double takes the shuffle-port work of the second transpose.
//
// One end's row from its cell's rows, w and beyond in every lane: the
// integrals T_i + w (f_a + w/2 df) + beyond f(end) and the points
// f_a + w df, in endAt()'s operations.
// Without kBeyond, `beyond` is taken as 0 (no lane of the batch is beyond
// the table).
template <bool kBeyond = true>
[[gnu::always_inline]] inline __m512d endRow(const PreintegralRows& r, __m512d w, __m512d beyond) {
  const __m512d value = _mm512_load_pd(r.value);
  const __m512d t1 = _mm512_fmadd_pd(w, _mm512_load_pd(r.curve), _mm512_load_pd(r.slope));  // points: df
  const __m512d row = _mm512_fmadd_pd(w, t1, value);
  if constexpr (!kBeyond) return row;
  // Beyond the table the integrals go on with the end's point values.
  return _mm512_mask3_fmadd_pd(beyond, _mm512_maskz_shuffle_f64x2(kAll, row, row, 0x4E), row, 0x0F);
}

// The row of the end before the next batch's first: lane 7's.
struct RowEnd {
  __m512d row;
  double x;
};

// The row of one scalar, as spansAt() computes it.
inline RowEnd rowEnd(const PreintegralTables& t, float scalar) {
  const Coordinates8 c = coordinates(t, _mm256_set1_ps(scalar));
  const int cell = _mm256_cvtsi256_si32(c.cell);
  return {endRow(t.rows[cell], c.w, c.beyond), _mm512_cvtsd_f64(c.x)};
}

// rowEnd() of a batch's front, without the table where the transfer
// function is empty around it: a front that allClear() would call clear
// (below PreintegralTables::clearBelow, or at or above clearAbove, a cell
// of margin for its coordinate's rounding) lies in a cell whose nodes
// have no extinction or colour, where every row is the same, exactly:
// all integrals 0 in the empty low end (the sums start at 0 and add
// zeros), the integrals at the last node in the empty high end, and the
// point values 0 (endRow()'s w and beyond terms then add exact zeros).
// After a batch of empty segments, and at a run's start, the front is
// mostly there; the table look-up it spares sat on the batch's chain of
// dependent loads.
inline RowEnd frontRow(const PreintegralTables& t, float scalar) {
  const EmptyEnd end = emptyEndOf(t, scalar);
  if (end == EmptyEnd::kNone) return rowEnd(t, scalar);
  const __m512d row = end == EmptyEnd::kLow ? _mm512_setzero_pd() : _mm512_load_pd(t.rows[t.entries - 1].value);
  return {row, _mm512_cvtsd_f64(coordinates(t, _mm256_set1_ps(scalar)).x)};
}

// The eight segments ending at these scalars, the first starting at
// `before`, which becomes the last of them.
[[gnu::always_inline]] inline Spans8 spansAt(const PreintegralTables& t, __m256 scalar, RowEnd& before) {
  const Coordinates8 c = coordinates(t, scalar);
  alignas(64) double w[8], beyond[8], x[8];
  alignas(32) std::int32_t cell[8];
  _mm512_store_pd(w, c.w);
  _mm512_store_pd(beyond, c.beyond);
  _mm512_store_pd(x, c.x);
  _mm256_store_si256(reinterpret_cast<__m256i*>(cell), c.cell);
  // Back minus front in lanes 0-3 (integrals), plus in lanes 4-7 (points).
  const __m512d sign = _mm512_setr_pd(-1, -1, -1, -1, 1, 1, 1, 1);
  __m512d d[8];
  __m512d previous = before.row;
  auto ends = [&](auto beyondTag) __attribute__((always_inline)) {
    for (int j = 0; j < 8; ++j) {
      const __m512d row = endRow<decltype(beyondTag)::value>(t.rows[cell[j]], _mm512_set1_pd(w[j]),
                                                             _mm512_set1_pd(beyond[j]));
      d[j] = _mm512_fmadd_pd(sign, previous, row);
      previous = row;
    }
  };
  // Scalars beyond the table's ends are rare (data outside the transfer
  // function's points).
  if (_mm512_cmp_pd_mask(c.beyond, _mm512_setzero_pd(), _CMP_NEQ_UQ)) ends(std::true_type{});
  else ends(std::false_type{});
  transpose8x8(d);
  Spans8 e;
  e.fx = _mm512_castsi512_pd(_mm512_maskz_alignr_epi64(kAll, _mm512_castpd_si512(c.x),
                                                       _mm512_castpd_si512(_mm512_set1_pd(before.x)), 7));
  e.dx = _mm512_sub_pd(c.x, e.fx);
  e.dT = d[0];
  e.sumTau = d[4];
  for (int k = 0; k < 3; ++k) {
    e.dK[k] = d[1 + k];
    e.sumK[k] = d[5 + k];
  }
  before = {previous, x[7]};
  return e;
}

}  // namespace pvr::core::preint

#endif
