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

PreintegratedTable::PreintegratedTable(const TransferFunctionSpec& tf, double step) {
  requireUsable(tf, step);
  const TableDomain domain(tf, kEntries);
  domain.mapping(scale_, offset_);
  const int n = kEntries;

  // The medium on a fine scalar grid (8 sub-entries per entry), so a
  // segment's integral resolves the transfer function between entries.
  const int fine = 8 * (n - 1) + 1;
  std::vector<Medium> media(fine);
  for (int i = 0; i < fine; ++i) media[i] = evaluateMedium(tf, domain.scalar(double(i) / 8.0));

  entries_.resize(std::size_t(n) * n);
  for (int f = 0; f < n; ++f) {
    for (int b = 0; b < n; ++b) {
      // Walk the scalar linearly from front to back in sub-segments of
      // constant medium, each integrated exactly, front to back.
      const int fi = 8 * f, bi = 8 * b;
      // One sub-segment per table entry crossed keeps the build near 10^7
      // steps; each reads the medium between fine-grid points.
      const int steps = std::max(1, std::abs(b - f));
      const double dl = step / steps;
      double r = 0, g = 0, bl = 0, transmit = 1;
      for (int k = 0; k < steps; ++k) {
        // Mid-point of sub-segment k on the fine grid (a half index away from both ends).
        const double pos = fi + (bi - fi) * (k + 0.5) / steps;
        const int i0 = int(std::floor(pos));
        const double w = pos - i0;
        const Medium& m0 = media[std::clamp(i0, 0, fine - 1)];
        const Medium& m1 = media[std::clamp(i0 + 1, 0, fine - 1)];
        const double tau = m0.tau + w * (m1.tau - m0.tau);
        const double alpha = -std::expm1(-tau * dl);
        const double weight = transmit * alpha;
        r += weight * (m0.r + w * (m1.r - m0.r));
        g += weight * (m0.g + w * (m1.g - m0.g));
        bl += weight * (m0.b + w * (m1.b - m0.b));
        transmit *= 1 - alpha;
      }
      entries_[std::size_t(f) * n + b] = {float(r), float(g), float(bl), float(1 - transmit)};
    }
  }
}

}  // namespace pvr::core
