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

// Transitional, for callers outside this file's owner (node/actions/
// collect.cpp, tests/node) until they use setFramePixels and
// proto::decompressPixels of an ImageFrame; remove then. framePixels compresses with exactly
// `compression` (no fallback); decompressPixels is proto::decompressPixels of
// a one-row image of `expected` bytes and throws pvr::Error (kBadFile).
std::vector<std::uint8_t> framePixels(const core::Image& frame, const std::array<double, 4>& background,
                                      proto::PixelFormat format, proto::Compression compression);
std::vector<std::uint8_t> decompressPixels(const std::vector<std::uint8_t>& bytes, std::size_t expected,
                                           proto::PixelFormat format, proto::Compression compression);

}  // namespace pvr::node
