#include "transfer.h"

#include <algorithm>
#include <cmath>

#include "error.h"
#include "image_srgb.h"

namespace pvr::core {

namespace {

// Interpolated control point at `scalar`: linear between points, clamped outside.
TransferPoint interpolate(const std::vector<TransferPoint>& pts, double scalar) {
  if (scalar <= pts.front().scalar) return pts.front();
  if (scalar >= pts.back().scalar) return pts.back();
  auto hi = std::upper_bound(pts.begin(), pts.end(), scalar,
                             [](double s, const TransferPoint& p) { return s < p.scalar; });
  auto lo = hi - 1;
  const double w = (scalar - lo->scalar) / (hi->scalar - lo->scalar);
  auto mix = [w](double a, double b) { return a + w * (b - a); };
  return {scalar, mix(lo->r, hi->r), mix(lo->g, hi->g), mix(lo->b, hi->b),
          mix(lo->opacity, hi->opacity)};
}

void requireUsable(const TransferFunctionSpec& tf, double step) {
  if (tf.points.empty())
    throw Error(ErrorCode::kInvalidArgument, "transfer function: no control points");
  if (!(tf.unitDistance > 0))
    throw Error(ErrorCode::kInternal, "transfer function: unit distance not resolved");
  if (!(step > 0)) throw Error(ErrorCode::kInternal, "transfer function: step must be > 0");
}

// A table of n entries over the control points' scalar range [smin, smax]:
// entry i (fractional for sub-entries) holds scalar(i), and a scalar s is
// looked up at s * scale + offset. A single point maps everything to entry 0.
struct TableDomain {
  double smin, smax;
  int n;

  TableDomain(const TransferFunctionSpec& tf, int entries)
      : smin(tf.points.front().scalar), smax(tf.points.back().scalar), n(entries) {}
  double scalar(double i) const { return smax > smin ? smin + (smax - smin) * i / (n - 1) : smin; }
  void mapping(float& scale, float& offset) const {
    const double s = smax > smin ? double(n - 1) / (smax - smin) : 0.0;
    scale = float(s);
    offset = float(-smin * s);
  }
};

}  // namespace

Medium evaluateMedium(const TransferFunctionSpec& tf, double scalar) {
  // Interpolated between the control points as given (display sRGB, as
  // ParaView interpolates its RGB space), then converted to linear light.
  const TransferPoint p = interpolate(tf.points, scalar);
  Medium m{srgbToLinear(p.r), srgbToLinear(p.g), srgbToLinear(p.b), 0};
  const double a = std::clamp(p.opacity, 0.0, 1.0);
  // Opacity 1 is an infinite extinction; keep it finite but saturating so
  // 1 - exp(-tau h) rounds to 1 for any step a renderer uses.
  m.tau = a >= 1.0 ? 1e30 : -std::log1p(-a) / tf.unitDistance;
  return m;
}

TransferTable::TransferTable(const TransferFunctionSpec& tf, double step) {
  requireUsable(tf, step);
  const TableDomain domain(tf, kEntries);
  domain.mapping(scale_, offset_);
  entries_.resize(kEntries);
  visiblePrefix_.assign(kEntries + 1, 0);
  for (int i = 0; i < kEntries; ++i) {
    const Medium m = evaluateMedium(tf, domain.scalar(i));
    // Opacity of one step: 1 - (1 - a)^(h / unit) = 1 - exp(-tau h).
    const double alpha = -std::expm1(-m.tau * step);
    entries_[i] = {float(m.r * alpha), float(m.g * alpha), float(m.b * alpha), float(alpha)};
    visiblePrefix_[i + 1] = visiblePrefix_[i] + (alpha > 0 ? 1 : 0);
  }
}

bool TransferTable::anyVisible(double lo, double hi) const {
  if (entries_.empty()) return false;
  // Entries i and i+1 both feed a lookup between them: widen by one each way.
  auto index = [this](double s) {
    return std::clamp(s * double(scale_) + double(offset_), 0.0, double(kEntries - 1));
  };
  const int a = std::max(0, int(std::floor(index(lo))) - 1);
  const int b = std::min(kEntries - 1, int(std::ceil(index(hi))) + 1);
  return visiblePrefix_[b + 1] - visiblePrefix_[a] > 0;
}

ExtinctionTable::ExtinctionTable(const TransferFunctionSpec& tf, double step) {
  requireUsable(tf, step);
  const TableDomain domain(tf, kEntries);
  domain.mapping(scale_, offset_);
  entries_.resize(kEntries);
  for (int i = 0; i < kEntries; ++i) {
    const Medium m = evaluateMedium(tf, domain.scalar(i));
    const double depth = m.tau * step;
    entries_[i] = {float(m.r * depth), float(m.g * depth), float(m.b * depth), float(depth)};
  }
}

PreintegratedTable::PreintegratedTable(const TransferFunctionSpec& tf) {
  requireUsable(tf, 1.0);
  const TableDomain domain(tf, kEntries);
  domain.mapping(scale_, offset_);
  const int n = kEntries;
  // Table coordinates per world scalar unit are folded into the integrals:
  // T and K are integrals over the table coordinate, and so is the
  // segment's difference quotient (preintegration.h).
  cells_.resize(n);
  opaqueColour_.resize(2 * std::size_t(n));
  for (int i = 0; i < n; ++i) {
    const Medium m = evaluateMedium(tf, domain.scalar(i));
    PreintegralCell& cell = cells_[i];
    // Opacity 1 is kept out of the sums (its extinction is infinite); the
    // colour an opaque segment shows is recorded apart below.
    const bool opaque = m.tau >= 1e30;
    cell.tau = opaque ? 0.0 : m.tau;
    const double c[3] = {m.r, m.g, m.b};
    for (int k = 0; k < 3; ++k) cell.k[k] = cell.tau * c[k];
    cell.opaque = opaque ? 1.0 : 0.0;
    opaqueColour_[2 * std::size_t(i)] = opaqueColour_[2 * std::size_t(i) + 1] =
        opaque ? Rgba{float(m.r), float(m.g), float(m.b), 1.0f} : Rgba{};
  }
  // Changes across each cell (none beyond the last node), and cumulative
  // integrals of the piecewise-linear node values (trapezoids).
  for (int i = 0; i < n; ++i) {
    PreintegralCell& a = cells_[i];
    const PreintegralCell& b = cells_[std::min(i + 1, n - 1)];
    a.dtau = b.tau - a.tau;
    for (int k = 0; k < 3; ++k) a.dk[k] = b.k[k] - a.k[k];
    a.dopaque = b.opaque - a.opaque;
  }
  cells_[0].T = cells_[0].M = cells_[0].O = 0;
  for (int k = 0; k < 3; ++k) cells_[0].K[k] = 0;
  for (int i = 1; i < n; ++i) {
    const PreintegralCell& a = cells_[i - 1];
    PreintegralCell& b = cells_[i];
    b.T = a.T + 0.5 * (a.tau + b.tau);
    // Integral over [i - 1, i] of x tau(x), tau linear: (i - 1) (a + b) / 2 + (a + 2 b) / 6.
    b.M = a.M + double(i - 1) * 0.5 * (a.tau + b.tau) + (a.tau + 2 * b.tau) / 6.0;
    for (int k = 0; k < 3; ++k) b.K[k] = a.K[k] + 0.5 * (a.k[k] + b.k[k]);
    b.O = a.O + 0.5 * (a.opaque + b.opaque);
  }
  // The cells as rows (PreintegralRows), for the batched kernel.
  rows_.resize(std::size_t(n));
  for (int i = 0; i < n; ++i) {
    const PreintegralCell& a = cells_[i];
    PreintegralRows& r = rows_[i];
    const double value[8] = {a.T, a.K[0], a.K[1], a.K[2], a.tau, a.k[0], a.k[1], a.k[2]};
    const double slope[8] = {a.tau, a.k[0], a.k[1], a.k[2], a.dtau, a.dk[0], a.dk[1], a.dk[2]};
    const double curve[8] = {0.5 * a.dtau, 0.5 * a.dk[0], 0.5 * a.dk[1], 0.5 * a.dk[2], 0, 0, 0, 0};
    std::copy(value, value + 8, r.value);
    std::copy(slope, slope + 8, r.slope);
    std::copy(curve, curve + 8, r.curve);
    if (a.opaque > 0) opaqueNodes_ = true;
  }
  // Cells that are not empty, counted from the first.
  visibleBelow_.assign(std::size_t(n), 0);
  for (int i = 1; i < n; ++i) {
    const PreintegralCell &a = cells_[i - 1], &b = cells_[i];
    const bool visible = a.tau > 0 || b.tau > 0 || a.opaque > 0 || b.opaque > 0;
    visibleBelow_[i] = visibleBelow_[i - 1] + (visible ? 1 : 0);
  }
  // The empty ends (PreintegralTables::clearBelow, clearAbove): allEmpty()
  // (preint_lanes.h) finds cells [cell(lo) - 1, cell(hi) + 1] empty, cell(x)
  // = min(int(clamp(x, 0, n - 1)), n - 2), when cell(hi) <= first - 2, which
  // for coordinates is hi < first - 1 (first >= 2), or when cell(lo) >=
  // last + 2, which is lo >= last + 2 (last + 2 <= n - 2). Without empty
  // cells between first and last, those are the only empty batches.
  int first = -1, last = -1;  // visible cells
  for (int i = 0; i + 1 < n; ++i)
    if (visibleBelow_[i + 1] > visibleBelow_[i]) {
      if (first < 0) first = i;
      last = i;
    }
  if (first < 0) {
    clearBelow_ = INFINITY;
    gaps_ = false;
  } else {
    clearBelow_ = first >= 2 ? float(first - 1) : -INFINITY;
    clearAbove_ = last + 2 <= n - 2 ? float(last + 2) : INFINITY;
    gaps_ = int(visibleBelow_[last + 1] - visibleBelow_[first]) < last - first + 1;
  }
  // The nearest opaque node at or below each node, then at or above it.
  for (int i = 1; i < n; ++i)
    if (cells_[i].opaque == 0) opaqueColour_[2 * std::size_t(i)] = opaqueColour_[2 * std::size_t(i - 1)];
  for (int i = n - 2; i >= 0; --i)
    if (cells_[i].opaque == 0)
      opaqueColour_[2 * std::size_t(i) + 1] = opaqueColour_[2 * std::size_t(i + 1) + 1];
}

PreintegralTables PreintegratedTable::tables() const {
  PreintegralTables t;
  t.cells = cells_.data();
  t.opaqueColour = opaqueColour_.data();
  t.visibleBelow = visibleBelow_.data();
  t.rows = rows_.data();
  t.opaqueNodes = opaqueNodes_;
  t.entries = int(cells_.size());
  t.scale = scale_;
  t.offset = offset_;
  t.clearBelow = clearBelow_;
  t.clearAbove = clearAbove_;
  t.gaps = gaps_;
  return t;
}

}  // namespace pvr::core
