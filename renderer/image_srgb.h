// The sRGB curve both ways: colours a user gives (transfer functions,
// backgrounds: display sRGB, as ParaView and colour pickers mean them)
// into linear light for rendering, and linear premultiplied frames into
// 8-bit sRGB for PNG files (image_io.h) and the wire's pixels
// (node/frame_pixels).
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
// The same, computed from the curve for each call (a pow): what
// linearToSrgb8's tables are checked against.
std::uint8_t linearToSrgb8ByCurve(double linear);

// An sRGB-encoded value (display colour, 1 = white) to linear light: the
// inverse of the curve above (x / 12.92 up to 0.04045, else
// ((x + 0.055) / 1.055)^2.4), continued above 1 for emissive colours
// brighter than white; negative and NaN give 0.
double srgbToLinear(double encoded);

// The full frame of `image` composited over `background` (straight RGBA,
// its colour display sRGB, converted to linear and premultiplied here) as
// 8-bit sRGB, straight-alpha RGBA, rows top to bottom.
std::vector<std::uint8_t> toSrgbRgba8(const Image& image, const std::array<double, 4>& background);

}  // namespace pvr::core
