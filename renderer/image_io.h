// Writing and reading frames: EXR for measurement, PNG for people.
//
// EXR holds the image as rendered: linear, premultiplied RGBA float32, the
// full frame (transparent outside the image's rect), NOT composited over the
// background, so error statistics see exactly what the renderer produced.
// PNG is the image composited over the scene's background and encoded with
// the sRGB transfer curve to 8-bit straight-alpha RGBA.
// Errors throw pvr::Error naming the path.
#pragma once

#include <array>
#include <cstdint>
#include <string>
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

void writeExr(const Image& image, const std::string& path);
void writePng(const Image& image, const std::array<double, 4>& background, const std::string& path);
// By extension (case-insensitive): ".exr" or ".png"; anything else throws.
void writeImage(const Image& image, const std::array<double, 4>& background, const std::string& path);

// Reads an OpenEXR file's R, G, B, A channels as stored (premultiplied
// linear; no A means opaque). The frame is the EXR display window, the
// image's rect its data window (clipped to the frame).
Image readExr(const std::string& path);

}  // namespace pvr::core
