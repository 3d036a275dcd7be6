#include "image.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "error.h"

namespace pvr::core {

PixelRect PixelRect::intersect(const PixelRect& o) const {
  PixelRect r{std::max(x0, o.x0), std::max(y0, o.y0), std::min(x1, o.x1), std::min(y1, o.y1)};
  if (r.empty()) return {};
  return r;
}

PixelRect PixelRect::unite(const PixelRect& o) const {
  if (empty()) return o;
  if (o.empty()) return *this;
  return {std::min(x0, o.x0), std::min(y0, o.y0), std::max(x1, o.x1), std::max(y1, o.y1)};
}

Image::Image(int frameWidth, int frameHeight, const PixelRect& rect)
    : frameWidth_(frameWidth), frameHeight_(frameHeight),
      rect_(rect.intersect({0, 0, frameWidth, frameHeight})),
      pixels_(std::size_t(rect_.width()) * std::size_t(rect_.height())) {}

Rgba Image::sample(int x, int y) const {
  if (x < rect_.x0 || x >= rect_.x1 || y < rect_.y0 || y >= rect_.y1) return {};
  return at(x, y);
}

Image Image::toFullFrame() const {
  Image full = fullFrame(frameWidth_, frameHeight_);
  for (int y = rect_.y0; y < rect_.y1; ++y)
    std::copy(row(y), row(y) + rect_.width(), full.row(y) + rect_.x0);
  return full;
}

void compositeUnder(Image& front, const Image& back) {
  const PixelRect r = back.rect();
  if (r.empty()) return;
  if (front.rect().intersect(r) != r)
    throw Error(ErrorCode::kInternal, "compositeUnder: front image does not cover the back image");
  for (int y = r.y0; y < r.y1; ++y) {
    Rgba* f = &front.at(r.x0, y);
    const Rgba* b = back.row(y);
    for (int x = 0; x < r.width(); ++x) {
      const float t = 1.0f - f[x].a;
      f[x].r += t * b[x].r;
      f[x].g += t * b[x].g;
      f[x].b += t * b[x].b;
      f[x].a += t * b[x].a;
    }
  }
}

static void requireSameFrame(const Image& a, const Image& b) {
  if (a.frameWidth() != b.frameWidth() || a.frameHeight() != b.frameHeight())
    throw Error(ErrorCode::kInvalidArgument, "image comparison: frames differ in size");
}

double maxAbsDifference(const Image& a, const Image& b) {
  return compareImages(a, b).maxAbs;
}

ImageError compareImages(const Image& test, const Image& reference) {
  requireSameFrame(test, reference);
  double sum = 0, worst = 0;
  for (int y = 0; y < test.frameHeight(); ++y)
    for (int x = 0; x < test.frameWidth(); ++x) {
      const Rgba p = test.sample(x, y), q = reference.sample(x, y);
      const double d[4] = {double(p.r) - q.r, double(p.g) - q.g, double(p.b) - q.b,
                           double(p.a) - q.a};
      for (double v : d) {
        sum += v * v;
        // A NaN anywhere is the worst possible error, never hidden by max().
        worst = std::isnan(v) ? std::numeric_limits<double>::infinity() : std::max(worst, std::abs(v));
      }
    }
  ImageError e;
  const double n = 4.0 * test.frameWidth() * test.frameHeight();
  e.rmse = n > 0 ? std::sqrt(sum / n) : 0;
  e.psnr = e.rmse > 0 ? 20.0 * std::log10(1.0 / e.rmse) : std::numeric_limits<double>::infinity();
  e.maxAbs = worst;
  return e;
}

}  // namespace pvr::core
