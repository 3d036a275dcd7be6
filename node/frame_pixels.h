// What the collector sends: a finished float frame as 8-bit sRGB over the
// scene background (RGB8, or RGBA8 with straight alpha). The wire
// compression of those bytes is protocol/pixel_codec.h.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "image.h"
#include "pvr_protocol.h"

namespace pvr::node {

// The uncompressed pixels of `frame` in `format`: rows top to bottom, 8-bit
// sRGB over `background`.
std::vector<std::uint8_t> srgbPixels(const core::Image& frame, const std::array<double, 4>& background,
                                     proto::PixelFormat format);

// Sets out.pixels and out.compression from `frame` (out.width, out.height,
// out.format already set): srgbPixels compressed with `wanted`, or
// uncompressed with kNone when compressing does not make them fewer
// (proto::setPixels).
void setFramePixels(proto::ImageFrame& out, const core::Image& frame, const std::array<double, 4>& background,
                    proto::Compression wanted);

}  // namespace pvr::node
