// Writing and reading frames: EXR for measurement, PNG for people.
// Library pvr_image_io (OpenImageIO): tools, tests and benches link it;
// pvr-node loads it only to write a file (node/image_output.h), so its
// ranks do not carry OpenImageIO's ~130 MB of libraries beside their bricks.
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
#include "image_srgb.h"

namespace pvr::core {

void writeExr(const Image& image, const std::string& path);
void writePng(const Image& image, const std::array<double, 4>& background, const std::string& path);
// By extension (case-insensitive): ".exr" or ".png"; anything else throws.
void writeImage(const Image& image, const std::array<double, 4>& background, const std::string& path);

// Reads an OpenEXR file's R, G, B, A channels as stored (premultiplied
// linear; no A means opaque). The frame is the EXR display window, the
// image's rect its data window (clipped to the frame).
Image readExr(const std::string& path);

// Reads an 8-bit PNG's R, G and B code values as stored, each / 255: no
// sRGB decoding, alpha not applied, alpha 0 in the image. For comparing
// another program's frame number for number (bench/speed_vs_error
// --peer-png: VTK writes the values it composited).
Image readPngCodes(const std::string& path);

}  // namespace pvr::core
