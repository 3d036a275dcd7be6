#include "coarse_frame.h"

#include <algorithm>
#include <cmath>

namespace pvr::node {

int reducedSize(int size, int reduction) { return std::max(1, (size + reduction - 1) / reduction); }

core::Image upscaleFrame(const core::Image& coarse, int width, int height) {
  const core::Image source = coarse.toFullFrame();
  const int sw = source.frameWidth(), sh = source.frameHeight();
  core::Image out = core::Image::fullFrame(width, height);
  // Output pixel centre x + 0.5 lies at (x + 0.5) * sw / width in the
  // source, whose pixel centres are at i + 0.5.
  const auto taps = [](int i, int n, int sn, int& lo, int& hi, float& w) {
    const double u = std::clamp((i + 0.5) * sn / n - 0.5, 0.0, double(sn - 1));
    lo = int(std::floor(u));
    hi = std::min(lo + 1, sn - 1);
    w = float(u - lo);
  };
  for (int y = 0; y < height; ++y) {
    int y0, y1;
    float wy;
    taps(y, height, sh, y0, y1, wy);
    for (int x = 0; x < width; ++x) {
      int x0, x1;
      float wx;
      taps(x, width, sw, x0, x1, wx);
      const core::Rgba &a = source.at(x0, y0), &b = source.at(x1, y0), &c = source.at(x0, y1), &d = source.at(x1, y1);
      const auto mix = [&](float core::Rgba::*ch) {
        const float top = a.*ch + (b.*ch - a.*ch) * wx, bottom = c.*ch + (d.*ch - c.*ch) * wx;
        return top + (bottom - top) * wy;
      };
      out.at(x, y) = {mix(&core::Rgba::r), mix(&core::Rgba::g), mix(&core::Rgba::b), mix(&core::Rgba::a)};
    }
  }
  return out;
}

ReducedImage::ReducedImage(core::ImageSpec& image, int reduction) : image_(image), full_(image) {
  image_.width = reducedSize(full_.width, reduction);
  image_.height = reducedSize(full_.height, reduction);
}

}  // namespace pvr::node
