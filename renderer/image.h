// Premultiplied linear RGBA float images with a screen-space rectangle.
//
// A brick renders only the pixels its box projects to; its Image covers that
// rectangle of the full frame. Pixels are premultiplied by alpha everywhere,
// so compositing is Porter-Duff "over" on four floats.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

namespace pvr::core {

// Half-open pixel rectangle [x0, x1) x [y0, y1); row 0 is the top of the frame.
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  int width() const { return x1 > x0 ? x1 - x0 : 0; }
  int height() const { return y1 > y0 ? y1 - y0 : 0; }
  bool empty() const { return width() == 0 || height() == 0; }
  PixelRect intersect(const PixelRect& o) const;
  PixelRect unite(const PixelRect& o) const;  // bounding rectangle of both
  friend bool operator==(const PixelRect&, const PixelRect&) = default;
};

struct Rgba {
  float r = 0, g = 0, b = 0, a = 0;
};

class Image {
 public:
  Image() = default;
  // A transparent image of `rect` inside a frame of frameWidth x frameHeight.
  Image(int frameWidth, int frameHeight, const PixelRect& rect);
  static Image fullFrame(int width, int height) { return Image(width, height, {0, 0, width, height}); }

  int frameWidth() const { return frameWidth_; }
  int frameHeight() const { return frameHeight_; }
  const PixelRect& rect() const { return rect_; }

  // Pixel at frame coordinates (x, y), which must lie inside rect().
  Rgba& at(int x, int y) { return pixels_[index(x, y)]; }
  const Rgba& at(int x, int y) const { return pixels_[index(x, y)]; }
  // Pixel at frame coordinates, transparent outside rect().
  Rgba sample(int x, int y) const;

  Rgba* row(int y) { return &pixels_[index(rect_.x0, y)]; }
  const Rgba* row(int y) const { return &pixels_[index(rect_.x0, y)]; }
  std::vector<Rgba>& pixels() { return pixels_; }
  const std::vector<Rgba>& pixels() const { return pixels_; }

  // This image extended to the full frame (transparent outside rect()).
  Image toFullFrame() const;

 private:
  std::size_t index(int x, int y) const {
    return std::size_t(y - rect_.y0) * std::size_t(rect_.width()) + std::size_t(x - rect_.x0);
  }

  int frameWidth_ = 0, frameHeight_ = 0;
  PixelRect rect_;
  std::vector<Rgba> pixels_;
};

// front = front over back, per pixel: c = c_f + (1 - a_f) c_b. `back` may
// cover any rectangle of the same frame; `front` must cover it (use
// toFullFrame or a united rect first).
void compositeUnder(Image& front, const Image& back);

// Largest absolute difference over all channels and pixels of two frames of
// the same size (full-frame comparison, transparent outside each rect).
double maxAbsDifference(const Image& a, const Image& b);

// Error statistics of `test` against `reference` over linear RGBA, full frame.
struct ImageError {
  double rmse = 0;
  double psnr = 0;    // dB, peak 1.0; infinity when identical
  double maxAbs = 0;
};
ImageError compareImages(const Image& test, const Image& reference);

}  // namespace pvr::core
