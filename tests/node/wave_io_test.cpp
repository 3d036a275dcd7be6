// The collector's image pieces (wave_io.h): a band is handed on, not
// copied, when nothing of it is cropped, so that rank 0 holds a frame once.
#include <catch2/catch.hpp>

#include "wave_io.h"

using namespace pvr;

namespace {

core::Image numbered(int width, int height, const core::PixelRect& rect) {
  core::Image image(width, height, rect);
  for (int y = rect.y0; y < rect.y1; ++y)
    for (int x = rect.x0; x < rect.x1; ++x) image.at(x, y) = {float(x), float(y), 0.5f, 1.0f};
  return image;
}

}  // namespace

TEST_CASE("cropping an image to a rect holding it hands the same pixels on, not a copy") {
  core::Image whole = numbered(64, 48, {0, 0, 64, 48});
  const core::Rgba* pixels = whole.pixels().data();
  const core::Image band = node::cropToRect(std::move(whole), {0, 0, 64, 48});
  CHECK(band.pixels().data() == pixels);
  CHECK(band.rect() == core::PixelRect{0, 0, 64, 48});
  core::Image part = numbered(64, 48, {8, 4, 40, 20});
  const core::Rgba* partPixels = part.pixels().data();
  CHECK(node::cropToRect(std::move(part), {0, 0, 64, 24}).pixels().data() == partPixels);
}

TEST_CASE("cropping an image reaching beyond the rect keeps exactly the pixels inside") {
  const core::Image whole = numbered(64, 48, {0, 0, 64, 48});
  const core::Image band = node::cropToRect(whole, {0, 24, 64, 48});
  REQUIRE(band.rect() == core::PixelRect{0, 24, 64, 48});
  CHECK(band.frameWidth() == 64);
  CHECK(band.frameHeight() == 48);
  for (int y = 24; y < 48; ++y)
    for (int x = 0; x < 64; ++x) {
      CHECK(band.at(x, y).r == float(x));
      CHECK(band.at(x, y).g == float(y));
    }
  CHECK(whole.pixels().size() == 64u * 48u);  // the original, passed as a copy, is untouched
}
