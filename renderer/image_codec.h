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

// Layout, little-endian; kImageCodecHeaderBytes of header, then payload:
//    0  magic "PVRI"
//    4  u8 version (1), u8 codec (kRaw, kRle or kRleZlib), u16 zero
//    8  u32 frame width, u32 frame height (each <= kImageCodecMaxSide)
//   16  i32 x0, y0, x1, y1: the rectangle, inside the frame
//   32  u64 payload size: for kRaw and kRle the bytes that follow; for
//       kRleZlib the size of the RLE payload the zlib stream inflates to
//   40  kRaw: the rectangle's rows of float RGBA (16 bytes a pixel).
//       kRle: per row of the rectangle, pairs (u32 empty, u32 active), each
//       followed by its active pixels' float RGBA, until the pairs cover the
//       row; every pair covers at least one pixel.
//       kRleZlib: the kRle payload as one zlib stream (level 1).
// Empty means all 16 bytes zero: -0.0 is active, so decoding is bit-exact.
inline constexpr std::size_t kImageCodecHeaderBytes = 40;
// What a header may ask for: the limits are checked before anything is
// allocated, and encode refuses images beyond them.
inline constexpr int kImageCodecMaxSide = 1 << 15;
inline constexpr std::uint64_t kImageCodecMaxPixels = std::uint64_t(1) << 26;  // 8192^2: 1 GiB

struct EncodedImage {
  std::vector<std::byte> bytes;  // self-describing: header with codec, frame size, rect
  std::size_t rawBytes = 0;      // what the rectangle costs as float RGBA
};

// Encodes the part of `image` inside `rect` (clipped to the image's rect);
// decoding gives an image of the same frame with that rectangle. Throws
// pvr::Error if the frame or rectangle exceeds the limits above.
EncodedImage encodeImage(const Image& image, const PixelRect& rect, ImageCodec codec);
EncodedImage encodeImage(const Image& image, ImageCodec codec);
// Throws pvr::Error (kBadFile) on malformed input: every size and run is
// checked against the limits, the rectangle and the bytes left before
// anything is allocated or copied; trailing bytes are an error too.
Image decodeImage(std::span<const std::byte> bytes);

}  // namespace pvr::core
