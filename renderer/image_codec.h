// Sparse image transfer: runs of empty and active pixels, optionally zlib.
//
// A partial image sent between ranks is mostly transparent; the sparse form
// stores, row by row of its rectangle, alternating run lengths of empty
// (alpha == 0 and colour == 0) and active pixels, and only the active
// pixels' RGBA. zlib at a low level on top helps where runs are short;
// encode() measures both and keeps the smaller unless told otherwise.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "image.h"

namespace pvr::core {

enum class ImageCodec : std::uint8_t {
  kRaw = 0,      // rectangle of float RGBA, no runs
  kRle = 1,      // runs of empty/active pixels
  kRleZlib = 2,  // runs, then zlib level 1
  kAuto = 255,   // encode: the smallest of kRle and kRleZlib; never written
};

struct EncodedImage {
  std::vector<std::byte> bytes;  // self-describing: header with codec, frame size, rect
  std::size_t rawBytes = 0;      // what the rectangle costs as float RGBA
};

// Encodes the part of `image` inside `rect` (clipped to the image's rect).
EncodedImage encodeImage(const Image& image, const PixelRect& rect, ImageCodec codec);
EncodedImage encodeImage(const Image& image, ImageCodec codec);
// Throws pvr::Error on malformed input (lengths checked before allocating).
Image decodeImage(std::span<const std::byte> bytes);

}  // namespace pvr::core
