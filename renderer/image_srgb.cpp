#include "image_srgb.h"

#include <algorithm>
#include <cmath>

namespace pvr::core {

namespace {

// The code value of v in (0, 1) by the curve's definition: one pow.
int curveCode(double v) {
  const double e = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
  return int(std::lround(e * 255.0));
}

// The code values without a pow per channel (one was 25 ms of a 512 x 512
// frame's conversion): the code rises with v, so the code of v is the
// number of thresholds (the least double of each code 1..255) at or below
// it. Buckets of 1/4096 hold at most one threshold each (the curve's
// steepest, near 0.003, is 0.8 codes per bucket), so the code is the
// bucket's first one, plus one past the next threshold: exactly curveCode.
class SrgbCodes {
 public:
  SrgbCodes() {
    for (int k = 1; k <= 255; ++k) {
      // Bisection down to adjacent doubles: curveCode(lo) < k <= curveCode(hi).
      double lo = 0, hi = 1;
      for (;;) {
        const double mid = lo + (hi - lo) / 2;
        if (mid <= lo || mid >= hi) break;
        (curveCode(mid) >= k ? hi : lo) = mid;
      }
      threshold_[std::size_t(k)] = hi;
    }
    threshold_[256] = 2;  // past every v < 1
    for (int i = 0; i < kBuckets; ++i) {
      const double start = double(i) / kBuckets;  // exact: a power of two apart
      int code = 0;
      while (code < 255 && threshold_[std::size_t(code) + 1] <= start) ++code;
      first_[std::size_t(i)] = std::uint8_t(code);
    }
  }
  std::uint8_t operator()(double v) const {  // v in (0, 1)
    int code = first_[std::size_t(v * kBuckets)];
    while (threshold_[std::size_t(code) + 1] <= v) ++code;
    return std::uint8_t(code);
  }

 private:
  static constexpr int kBuckets = 4096;
  std::array<double, 257> threshold_{};  // [k]: the least v of code k (k = 1..255)
  std::array<std::uint8_t, kBuckets> first_{};
};

}  // namespace

std::uint8_t linearToSrgb8(double v) {
  if (!(v > 0)) return 0;  // also NaN
  if (v >= 1) return 255;
  static const SrgbCodes codes;
  return codes(v);
}

std::uint8_t linearToSrgb8ByCurve(double v) {
  if (!(v > 0)) return 0;
  if (v >= 1) return 255;
  return std::uint8_t(curveCode(v));
}

double srgbToLinear(double x) {
  if (!(x > 0)) return 0;  // also NaN
  return x <= 0.04045 ? x / 12.92 : std::pow((x + 0.055) / 1.055, 2.4);
}

std::vector<std::uint8_t> toSrgbRgba8(const Image& image, const std::array<double, 4>& background) {
  const int w = image.frameWidth(), h = image.frameHeight();
  // The background is given straight, in display sRGB; "over" needs it
  // linear and premultiplied.
  const double bgA = background[3];
  const double bg[4] = {srgbToLinear(background[0]) * bgA, srgbToLinear(background[1]) * bgA,
                        srgbToLinear(background[2]) * bgA, bgA};
  std::vector<std::uint8_t> out(std::size_t(w) * std::size_t(h) * 4);
  std::uint8_t* o = out.data();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x, o += 4) {
      // Composite (premultiplied over), then divide by alpha: PNG is straight alpha.
      const Rgba p = image.sample(x, y);
      const double t = 1.0 - double(p.a);
      const double a = double(p.a) + t * bg[3];
      const double c[3] = {double(p.r) + t * bg[0], double(p.g) + t * bg[1], double(p.b) + t * bg[2]};
      for (int i = 0; i < 3; ++i) o[i] = a > 0 ? linearToSrgb8(c[i] / a) : 0;
      o[3] = std::uint8_t(std::lround(std::clamp(std::isnan(a) ? 0.0 : a, 0.0, 1.0) * 255.0));
    }
  return out;
}

}  // namespace pvr::core
