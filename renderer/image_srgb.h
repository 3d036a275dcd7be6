// Linear premultiplied frames to 8-bit sRGB: PNG files (image_io.h) and
// the pixels of the wire (node/frame_pixels) share these conversions.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "image.h"

namespace pvr::core {

// Linear value in [0, 1] (clamped; NaN -> 0) to an 8-bit sRGB code value,
// rounded to nearest: IEC 61966-2-1 curve (12.92 x below 0.0031308, else
// 1.055 x^(1/2.4) - 0.055).
std::uint8_t linearToSrgb8(double linear);

// The full frame of `image` composited over `background` (straight RGBA,
// premultiplied here) as 8-bit sRGB, straight-alpha RGBA, rows top to bottom.
std::vector<std::uint8_t> toSrgbRgba8(const Image& image, const std::array<double, 4>& background);

}  // namespace pvr::core
