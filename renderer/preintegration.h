// Pre-integration: one ray segment's colour and opacity from the scalars at
// its two ends, the scalar taken to vary linearly between them.
//
// No 2D table. Along a segment of world length L whose scalar runs
// linearly from x_f to x_b (table coordinates), the optical depth is
//   D = L * (T(x_b) - T(x_f)) / (x_b - x_f),   T(x) = integral of tau over x,
// exactly, and the extinction-weighted mean colour is
//   (K(x_b) - K(x_f)) / (T(x_b) - T(x_f)),     K(x) = integral of c tau over x.
// T and K are tabulated at the nodes of the 1D classification table and
// integrated exactly between them for tau and c tau linear between nodes
// (the same piecewise-linear transfer function the plain table samples),
// in double: a difference of two cumulative sums must keep the faint
// segments' few digits. The segment emits its mean colour times
// 1 - exp(-D); only the segment's self-attenuation of a colour that
// changes along it is left out, an O(h^3) term per segment.
//
// Opacity 1 (infinite extinction) is kept out of the sums: a segment whose
// scalars reach an opaque scalar is opaque and shows the colour of the
// first opaque scalar met from its front.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "image.h"

namespace pvr::core {

// One cell of the integral table, [i, i + 1] in table coordinates, across
// which the transfer function is linear: the values at node i and their
// changes to node i + 1, per world unit and table coordinate. Two 64-byte
// rows, so that the batched kernel loads a cell as two vectors and
// transposes eight of them into one vector per field (preint_lanes.h).
struct alignas(64) PreintegralCell {
  // Row 0: extinction and the cumulative integrals.
  double tau;     // extinction at node i; 0 where the node is opaque
  double dtau;    // at node i + 1 minus at node i
  double T;       // integral of tau from node 0 to node i
  double M;       // integral of x tau from node 0 (x: table coordinate), for the centroid
  double K[3];    // integral of c tau from node 0
  double O;       // integral of `opaque` from node 0
  // Row 1: colour and opacity, and their changes across the cell.
  double k[3];    // c tau, linear colour times extinction (0 where opaque)
  double dk[3];
  double opaque;  // 1 where the opacity is 1, else 0
  double dopaque;
};
static_assert(sizeof(PreintegralCell) == 128 && offsetof(PreintegralCell, k) == 64);

// The same cell as three rows of the polynomials in w (the coordinate's
// fraction across the cell) that give a segment end's values, for the
// batched kernel's unshaded look-up without opaque nodes
// (preint_lanes.h spansAt()): each end is computed as one row,
//   lanes 0-3: T, K0, K1, K2 at w:  value + w (slope + w curve),
//   lanes 4-7: tau, k0, k1, k2 at w: value + w slope (curve 0),
// so that consecutive ends' differences (integrals) and sums (means) are
// one vector operation per segment and a single 8x8 transpose turns eight
// segments into one vector per field; the two-row cell took two
// transposes and carried 14 vectors of ends from segment to segment. The
// values are the cell's, in double: differences of the cumulative sums
// keep the faint segments' digits exactly as PreintegralCell's do (and
// curve = slope / 2 is exact, so each end is endsAt()'s, to an ulp).
struct alignas(64) PreintegralRows {
  double value[8];  // T K0 K1 K2 at node i | tau k0 k1 k2 at node i
  double slope[8];  // tau k0 k1 k2 at node i | their changes to node i + 1
  double curve[8];  // their changes to node i + 1, halved | 0
};
static_assert(sizeof(PreintegralRows) == 192);

// Where the pre-integration's tables are, for the kernels.
struct PreintegralTables {
  const PreintegralCell* cells = nullptr;  // `entries` cells (the last one: its node only)
  const Rgba* opaqueColour = nullptr;      // [2 * entries]: per node, the colour of the nearest
                                           // opaque node at or below it, then at or above it
  const std::uint32_t* visibleBelow = nullptr;  // [entries]: cells below cell i with extinction or
                                               // opacity 1 at either node (the batched kernel's
                                               // test for a batch of empty segments)
  const PreintegralRows* rows = nullptr;   // `entries` cells as rows (PreintegralRows)
  int entries = 0;
  float scale = 0, offset = 0;             // table coordinate = scalar * scale + offset
  bool opaqueNodes = true;                 // some node has opacity 1 (rows then unused)
  // The empty ends, in table coordinates, with a cell of margin for a
  // coordinate's float rounding: a batch whose ends all lie below
  // `clearBelow`, or all at or above `clearAbove`, integrates nothing
  // (preint::allClear()). With no visible cell, every finite coordinate is
  // below clearBelow.
  float clearBelow = -INFINITY, clearAbove = INFINITY;
  bool gaps = true;  // empty cells between the first visible cell and the last
};

// The empty end a scalar's table coordinate lies in (below clearBelow, at
// or above clearAbove, or neither; NaN: neither), the coordinate computed
// as preint::allClear() computes it.
enum class EmptyEnd { kNone, kLow, kHigh };
inline EmptyEnd emptyEndOf(const PreintegralTables& t, float scalar) {
  const float x = std::fma(scalar, t.scale, t.offset);
  return x < t.clearBelow ? EmptyEnd::kLow : x >= t.clearAbove ? EmptyEnd::kHigh : EmptyEnd::kNone;
}

// The one empty end whose cells pre-integrated batches skip by (ClearEnds::
// ofSegments, clear_cells.h), the low one where the table has one: a
// segment from one end to the other crosses the visible values between.
inline EmptyEnd segmentsClearEnd(const PreintegralTables& t) {
  return t.clearBelow > -INFINITY ? EmptyEnd::kLow : EmptyEnd::kHigh;
}

namespace preint {

// Segments whose ends are closer than this (table coordinates) take the
// mean of their ends' point values: the difference quotient would lose
// digits, and the trapezoid is exact to 1e-5 of a node's variation there.
inline constexpr double kMinSpan = 1e-2;

// The rays' sample spacing for pre-integration at `step` (world units) on a
// grid whose smallest spacing is `voxel`: the step, split into equal
// segments of at most one voxel. A segment takes the scalar linear between
// its two end samples; across more than a voxel the field between them
// (kinked at every cell face, curved by features a few voxels wide) is no
// longer linear, and the segments erred more than point samples at the
// same step (the unshaded peer scene at 2 voxels: RMSE 1.25e-3 against
// 9.5e-4; bench/results/preintegration.txt). Split, they integrate the
// reconstruction at the voxel's scale, at the cost of a step of a voxel.
// The split samples t0 + k step / n include the step's own, and n is the
// same on every brick, so bricks still equal the whole.
inline double sampleSpacing(double step, double voxel) {
  const double n = std::ceil(step / voxel - 1e-9);
  return n > 1 ? step / n : step;
}

// The integrals at one scalar (a segment end).
struct End {
  double x = 0;  // table coordinate, unclamped
  double tau = 0, k[3] = {0, 0, 0}, T = 0, M = 0, K[3] = {0, 0, 0}, opaque = 0, O = 0;
};

// Outside the nodes the transfer function is clamped, so the integrals go
// on linearly with the end node's values.
[[gnu::always_inline]] inline End endAt(const PreintegralTables& t, float scalar) {
  End e;
  e.x = double(scalar) * double(t.scale) + double(t.offset);
  const double last = double(t.entries - 1);
  const double xc = std::clamp(e.x, 0.0, last);
  const int i = std::min(int(xc), t.entries - 2);
  const double w = xc - double(i), beyond = e.x - xc;
  const PreintegralCell& a = t.cells[i];
  // Integral over [i, i + w] of a linear f: w * (f_a + w/2 (f_b - f_a)).
  auto point = [w](double fa, double df) __attribute__((always_inline)) { return fa + w * df; };
  auto partial = [w](double fa, double df) __attribute__((always_inline)) {
    return w * (fa + 0.5 * w * df);
  };
  e.tau = point(a.tau, a.dtau);
  e.T = a.T + partial(a.tau, a.dtau) + beyond * e.tau;
  // Integral over [i, i + w] of (i + u) tau(u), tau linear; beyond, tau constant.
  e.M = a.M + double(i) * partial(a.tau, a.dtau) + w * w * (0.5 * a.tau + w * a.dtau * (1.0 / 3)) +
        0.5 * e.tau * beyond * (e.x + xc);
  for (int c = 0; c < 3; ++c) {
    e.k[c] = point(a.k[c], a.dk[c]);
    e.K[c] = a.K[c] + partial(a.k[c], a.dk[c]) + beyond * e.k[c];
  }
  e.opaque = point(a.opaque, a.dopaque);
  e.O = a.O + partial(a.opaque, a.dopaque) + beyond * e.opaque;
  return e;
}

// The colour of the first opaque scalar met going from table coordinate
// `front` towards `back`.
[[gnu::noinline, gnu::cold]] inline Rgba opaqueSegment(const PreintegralTables& t, double front, double back) {
  const double xc = std::clamp(front, 0.0, double(t.entries - 1));
  const bool up = back >= front;
  const std::size_t below = 2 * std::size_t(std::floor(xc)), above = 2 * std::size_t(std::ceil(xc)) + 1;
  // The opaque node ahead of the front; none ahead: the one in the front's own cell.
  Rgba c = t.opaqueColour[up ? above : below];
  if (!(c.a > 0)) c = t.opaqueColour[up ? below : above];
  c.a = 1.0f;
  return c;
}

// Where a segment of optical depth `depth` and opacity `alpha` (exactly
// 1 - exp(-depth)) emits, in fractions of its length, if it were
// homogeneous: the variance of t e^(-depth t) over [0, 1],
// 1/D^2 - (1 - alpha)/alpha^2; below depth 1e-2, where that difference
// cancels digits, its series 1/12 - D^2/240 (the next term, D^4/6048, is
// below 2e-12 there).
inline double emissionVariance(double depth, double alpha) {
  return depth < 1e-2 ? 1.0 / 12 - depth * depth / 240 : 1 / (depth * depth) - (1 - alpha) / (alpha * alpha);
}

// The segment from `front` to `back`, `length` world units long:
// premultiplied colour and opacity. `centre` and `spread` (if given) get
// where in the segment (0: front, 1: back) to light it: the two points
// centre -+ spread, the centroid of its emission -+ the emission's
// standard deviation, are the Gauss rule for lighting that varies along
// the segment (exact to second order; lighting at the centroid alone is
// exact to first order, and its error dominated pre-integration's on
// shaded scenes: bench/results/preintegration.txt).
[[gnu::always_inline]] inline Rgba segment(const PreintegralTables& t, const End& front,
                                           const End& back, double length, float* centre = nullptr,
                                           float* spread = nullptr) {
  const double dx = back.x - front.x;
  const bool wide = std::abs(dx) > kMinSpan;
  if ((wide && back.O != front.O) || front.opaque > 0 || back.opaque > 0) {
    if (centre) *centre = 0.5f;  // lit at its middle
    if (spread) *spread = 0.0f;
    return opaqueSegment(t, front.x, back.x);
  }
  double tau, k[3];
  if (wide) {
    const double inv = 1.0 / dx;
    tau = (back.T - front.T) * inv;
    for (int c = 0; c < 3; ++c) k[c] = (back.K[c] - front.K[c]) * inv;
  } else {
    tau = 0.5 * (front.tau + back.tau);
    for (int c = 0; c < 3; ++c) k[c] = 0.5 * (front.k[c] + back.k[c]);
  }
  if (!(tau > 0)) return {};
  const double depth = tau * length;
  const double alpha = -std::expm1(-depth);
  if (centre) {
    // The extinction's centroid along the segment (from the first moment;
    // near-equal ends: from the ends' extinctions, linear between them),
    // moved towards the front as self-attenuation weights it (exact for a
    // homogeneous segment: 1/D - 1/(e^D - 1) of its length).
    double at;
    if (wide) {
      at = ((back.M - front.M) / (back.T - front.T) - front.x) / dx;
    } else {
      const double sum = front.tau + back.tau;
      at = sum > 0 ? (front.tau + 2 * back.tau) / (3 * sum) : 0.5;
    }
    at += depth < 1e-3 ? -depth / 12 : 1 / depth - 1 / std::expm1(depth) - 0.5;
    *centre = float(std::clamp(at, 0.0, 1.0));
  }
  if (spread) *spread = float(std::sqrt(std::max(emissionVariance(depth, alpha), 0.0)));
  const double w = alpha / tau;  // mean colour c = k / tau, times alpha
  return {float(k[0] * w), float(k[1] * w), float(k[2] * w), float(alpha)};
}

}  // namespace preint

}  // namespace pvr::core
