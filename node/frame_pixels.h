// What the collector sends: a finished float frame as 8-bit sRGB over the
// scene background (RGB8, or RGBA8 with straight alpha), compressed.
//
// Compression kRle is a run-length code of whole pixels: runs of identical
// pixels as one byte (run length - 1, so 1..256) followed by the pixel's
// channels; it suits the flat background of volume images. kZlib is an RFC
// 1950 stream of the uncompressed bytes.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "image.h"
#include "pvr_protocol.h"

namespace pvr::node {

std::vector<std::uint8_t> framePixels(const core::Image& frame, const std::array<double, 4>& background,
                                      proto::PixelFormat format, proto::Compression compression);

// The inverse of the compression step (tests, clients): the uncompressed
// bytes of width * height * channels. Throws pvr::Error on malformed input.
std::vector<std::uint8_t> decompressPixels(const std::vector<std::uint8_t>& bytes, std::size_t expected,
                                           proto::PixelFormat format, proto::Compression compression);

}  // namespace pvr::node
