#include "image_srgb.h"

#include <algorithm>
#include <cmath>

namespace pvr::core {

std::uint8_t linearToSrgb8(double v) {
  if (!(v > 0)) return 0;  // also NaN
  if (v >= 1) return 255;
  const double e = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
  return std::uint8_t(std::lround(e * 255.0));
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
